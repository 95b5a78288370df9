// The bridge that lets one header compile as GLSL (Vulkan, #version 450 with GL_GOOGLE_include_directive) and as C++
// with GLM. Shared headers are written in the common subset of both languages:
//  - float literals carry the f suffix (GLM does not mix float and double operands);
//  - parameters are declared with TY_IN / TY_OUT / TY_INOUT, functions with TY_FUNC, constants with TY_CONST;
//  - on the C++ side everything lives in namespace tyndall::shader, opened and closed by TY_BEGIN / TY_END, where the
//    GLSL built-in types and functions are brought in by name (using-declarations; no `using namespace`).
// Model: nvpro_core's nvvkhl/shaders/bsdf_functions.h (OUT_TYPE / INOUT_TYPE / ARRAY_TYPE).
#ifndef TY_SHARED_COMPAT_H
#define TY_SHARED_COMPAT_H

#ifdef __cplusplus

#include <glm/glm.hpp>
#include <glm/gtc/bitfield.hpp>
#include <cstdint>

namespace tyndall::shader {
using uint = std::uint32_t;
using glm::bvec3;
using glm::dvec2;
using glm::dvec3;
using glm::ivec2;
using glm::ivec3;
using glm::mat3;
using glm::mat4;
using glm::uvec2;
using glm::uvec3;
using glm::uvec4;
using glm::vec2;
using glm::vec3;
using glm::vec4;

using glm::abs;
using glm::acos;
using glm::all;
using glm::any;
using glm::asin;
using glm::atan;
using glm::bitfieldReverse;
using glm::ceil;
using glm::clamp;
using glm::cos;
using glm::cross;
using glm::distance;
using glm::dot;
using glm::exp;
using glm::floatBitsToUint;
using glm::floor;
using glm::fract;
using glm::greaterThan;
using glm::inversesqrt;
using glm::isinf;
using glm::isnan;
using glm::length;
using glm::lessThan;
using glm::log;
using glm::max;
using glm::min;
using glm::mix;
using glm::normalize;
using glm::pow;
using glm::reflect;
using glm::sign;
using glm::sin;
using glm::sqrt;
using glm::step;
using glm::tan;
using glm::uintBitsToFloat;
}  // namespace tyndall::shader

#define TY_BEGIN namespace tyndall::shader {
#define TY_END }
#define TY_FUNC inline
#define TY_CONST inline constexpr
#define TY_IN(T) const T&
#define TY_OUT(T) T&
#define TY_INOUT(T) T&

#else  // GLSL

#define TY_BEGIN
#define TY_END
#define TY_FUNC
#define TY_CONST const
#define TY_IN(T) in T
#define TY_OUT(T) out T
#define TY_INOUT(T) inout T

#endif

#endif  // TY_SHARED_COMPAT_H
