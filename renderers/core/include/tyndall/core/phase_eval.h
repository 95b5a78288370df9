// A phase function's value at the cosine mu of the scattering angle, per steradian, by the code the renderers use
// (shaders/shared/phase.h, in float): for plots and checks outside the renderers (the studio's phase panel).
#pragma once

#include "tyndall/core/scene.h"

namespace tyndall {

double phaseValue(const PhaseFunction& phase, double mu);

}  // namespace tyndall
