// Collimated single scattering in a convex homogeneous medium (Velinov and Mitchell, "Collimated Whole Volume Light
// Scattering in Homogeneous Finite Media", ../shared/papers/001): the analytic unoccluded integral over the trapezoid
// segments of the light-view section (Sec. 4, Eq. 4-8), whole-volume distance sampling and its pdf (Sec. 5,
// Eq. 9-11), and the classic samplers the paper compares against. Shared by GLSL and C++; the core is written once in
// wvds_impl.h and instantiated here in float and, where doubles exist (C++, or GLSL with TY_ENABLE_DOUBLE), in double.
//
// The derivation is in docs/wvds.md. In short: along the camera ray x(t) = o + t d, a point inside a convex medium
// {x : dot(n_f, x) <= w_f} reaches the boundary towards the light (direction l, from the point to the light) after
//   d_m(t) = min over the faces with dot(n_f, l) > 0 of (w_f - dot(n_f, x(t))) / dot(n_f, l),
// a minimum of linear functions of t: concave and piecewise linear, with one piece per face it crosses (at most 3 for
// a box: the paper's trapezoid segments). The light's path through the medium, from the camera's entry point tIn to
// x(t) and on to the boundary, has length P(t) = t - tIn + d_m(t), linear on each piece: P = p0 + c (t - t0) with the
// paper's slope c = 1 + d d_m/dt. Each piece integrates in closed form (Eq. 6), and sampling t with density
// e^{-sigma P(t)} / T_total inverts it piece by piece (Eq. 9-11).
//
// The includer defines, after including this header, the accessor
//   vec4 wvdsPlane(int i);   plane i as (n, w): the half-space dot(n, x) <= w, n of unit length
// over wherever it keeps the planes (a storage buffer in GLSL, the scene bound to the thread in C++).
#ifndef TY_SHARED_WVDS_H
#define TY_SHARED_WVDS_H

#include "compat.h"
#include "complex.h"
#include "constants.h"

TY_BEGIN

// Faces of the medium (6 for a box) and pieces of d_m along a ray (at most one per face with dot(n, l) > 0). A shader
// may lower TY_WVDS_MAX_PLANES before including this header: its loops then unroll and its arrays stay in registers,
// which on lavapipe halves the cost of a sample (arrays indexed at run time live in memory there).
// TY_WVDS_BOX says the medium is a box, its planes in pairs of opposite normals (boxHalfSpaces): of each pair only the
// face towards the light counts, so the envelope has 3 lines and at most 3 segments.
#ifndef TY_WVDS_MAX_PLANES
#define TY_WVDS_MAX_PLANES 16
#endif
TY_CONST int kWvdsMaxPlanes = TY_WVDS_MAX_PLANES;
#ifdef TY_WVDS_BOX
TY_CONST int kWvdsLines = 3;
#else
TY_CONST int kWvdsLines = TY_WVDS_MAX_PLANES;
#endif
TY_CONST int kWvdsMaxSegments = kWvdsLines;

vec4 wvdsPlane(int i);  // supplied by the includer (see above)

TY_END

// The series in wvds_impl.h stop where their next term is below the precision's roundoff: phi's to x^k / (k + 1)! for
// x < 1/2 (float: k = 7, 1e-8 relative; double: k = 12, 1e-15), log(1 - y)'s to y^k / k for y < 1/16 (float: k = 7,
// 5e-10; double: k = 14, 5e-19).
#define TY_R float
#define TY_R3 vec3
#define TY_RS(name) name##_float
#define TY_WVDS_PHI_TERMS 8
#define TY_WVDS_LOG_TERMS 7
#include "wvds_impl.h"
#undef TY_R
#undef TY_R3
#undef TY_RS
#undef TY_WVDS_PHI_TERMS
#undef TY_WVDS_LOG_TERMS

#ifdef TY_HAS_DOUBLE
#define TY_R double
#define TY_R3 dvec3
#define TY_RS(name) name##_double
#define TY_WVDS_PHI_TERMS 13
#define TY_WVDS_LOG_TERMS 14
#include "wvds_impl.h"
#undef TY_R
#undef TY_R3
#undef TY_RS
#undef TY_WVDS_PHI_TERMS
#undef TY_WVDS_LOG_TERMS
#endif

#endif  // TY_SHARED_WVDS_H
