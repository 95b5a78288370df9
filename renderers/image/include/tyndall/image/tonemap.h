// Display transforms: linear scene-referred RGB (Rec. 709 primaries, docs/conventions.md) times 2^exposure, then one of
// these operators, to display-encoded sRGB values in [0, 1]. The studio's viewport and every PNG use them; metrics
// (PSNR) always use the plain sRGB one, so that numbers never depend on how an image is looked at.
#pragma once

#include <array>
#include <string>
#include <vector>

namespace tyndall {

enum class Tonemap {
    Srgb,        // the sRGB transfer function, clamped (what a PNG of the linear values shows)
    Reinhard,    // L / (1 + L) on luminance, hue kept (Reinhard et al. 2002, Eq. 3), then sRGB
    Aces,        // Narkowicz's fit of the ACES filmic curve, per channel (2016), then sRGB
    FalseColour  // log2 of luminance over [kFalseColourMinEv, kFalseColourMaxEv] in viridis
};

constexpr double kFalseColourMinEv = -10.0, kFalseColourMaxEv = 2.0;

// "srgb", "reinhard", "aces", "falsecolour", in the order of the enum.
const std::vector<std::string>& tonemapNames();
// Throws InputError naming `where` and the allowed names for an unknown one.
Tonemap tonemapFromName(const std::string& name, const std::string& where);

// Display-encoded RGB in [0, 1] of one linear pixel. NaN channels count as 0.
std::array<float, 3> tonemapRgb(float r, float g, float b, double exposure, Tonemap op);

}  // namespace tyndall
