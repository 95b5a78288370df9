// GPU data layouts are declared once, in shaders/shared; here C++ checks that its view of them matches std430.
#include "shared/bsdf.h"
#include "shared/camera.h"
#include "shared/phase.h"

#include <cstddef>

namespace tyndall::shader {

static_assert(sizeof(PhaseParams) == 4 * 5 + 4 * kMaxLegendreTerms, "PhaseParams: five 4-byte scalars + the array");
static_assert(offsetof(PhaseParams, legendre) == 20, "PhaseParams::legendre follows the scalars (std430 stride 4)");
static_assert(alignof(PhaseParams) == 4, "PhaseParams holds 4-byte members only");

static_assert(sizeof(CameraParams) == 64, "CameraParams: four vec3 + float pairs");
static_assert(offsetof(CameraParams, forward) == 16 && offsetof(CameraParams, right) == 32 &&
                  offsetof(CameraParams, up) == 48,
              "each vec3 of CameraParams starts a 16-byte slot (std430)");

static_assert(sizeof(MaterialParams) == 48, "MaterialParams: std430 size");
static_assert(offsetof(MaterialParams, albedo) == 16, "vec3 albedo starts on a 16-byte boundary in std430");
static_assert(offsetof(MaterialParams, pad1) == 28, "the float after albedo fills its vec4 slot");
static_assert(offsetof(MaterialParams, f0) == 32, "vec3 f0 starts on a 16-byte boundary in std430");
static_assert(offsetof(MaterialParams, pad2) == 44, "the float after f0 fills its vec4 slot");

}  // namespace tyndall::shader
