// Colour maps for false colour and differences, t in [0, 1], returning linear RGB (so that writeImage's sRGB encoding
// reproduces the map's sRGB values).
#pragma once

#include "tyndall/core/scene.h"

namespace tyndall {

Rgb viridis(double t);
Rgb magma(double t);      // FLIP's error maps: black (0) - purple - orange - pale yellow (1)
Rgb diverging(double t);  // blue - white - red, white at 0.5

}  // namespace tyndall
