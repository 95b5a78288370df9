// Scene data converted to the plain structs of the shared GLSL/C++ headers (shaders/shared/), which every renderer
// uses on the CPU and uploads to the GPU: one conversion for all of them.
#pragma once

#include "shared/bsdf.h"
#include "shared/camera.h"
#include "shared/phase.h"
#include "tyndall/core/scene.h"

namespace tyndall {

shader::CameraParams toCameraParams(const Camera& camera);
shader::PhaseParams toPhaseParams(const PhaseFunction& phase);
shader::MaterialParams toMaterialParams(const Material& material);

}  // namespace tyndall
