// The rasterised closest hits that shared/primary_hits.h reads when a kernel is compiled with TY_PRIMARY_HITS: one
// storage buffer at TY_PRIMARY_HITS_BINDING (chosen by the includer), one vec4 record per grid sample.
#ifndef TY_PRIMARY_HITS_GLSL
#define TY_PRIMARY_HITS_GLSL

#ifdef TY_PRIMARY_HITS
layout(std430, set = 0, binding = TY_PRIMARY_HITS_BINDING) readonly buffer PrimaryHits { vec4 primaryHits[]; };
vec4 primaryHitRecord(int index) { return primaryHits[index]; }
#endif

#include "../shared/primary_hits.h"

#endif  // TY_PRIMARY_HITS_GLSL
