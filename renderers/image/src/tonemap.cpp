#include "tyndall/image/tonemap.h"

#include "tyndall/core/error.h"
#include "tyndall/image/colour_map.h"
#include "tyndall/image/image_io.h"

#include <algorithm>
#include <cmath>

namespace tyndall {

const std::vector<std::string>& tonemapNames() {
    static const std::vector<std::string> names = {"srgb", "reinhard", "aces", "falsecolour"};
    return names;
}

Tonemap tonemapFromName(const std::string& name, const std::string& where) {
    const std::vector<std::string>& names = tonemapNames();
    const auto it = std::find(names.begin(), names.end(), name);
    if (it == names.end()) {
        std::string allowed;
        for (const std::string& n : names) allowed += (allowed.empty() ? "" : ", ") + n;
        throw InputError(where + ": unknown tonemap operator \"" + name + "\" (allowed: " + allowed + ")");
    }
    return Tonemap(it - names.begin());
}

namespace {

float finiteOrZero(float v) { return std::isfinite(v) ? v : 0.0f; }

// Rec. 709 luminance of linear RGB.
float luminance(float r, float g, float b) { return 0.2126f * r + 0.7152f * g + 0.0722f * b; }

// Narkowicz, "ACES Filmic Tone Mapping Curve" (2016): a rational fit of the ACES RRT + ODT for sRGB, with his 0.6
// pre-scale so that exposure 0 matches the reference transform's mid grey.
float acesFit(float x) {
    x *= 0.6f;
    return std::clamp(x * (2.51f * x + 0.03f) / (x * (2.43f * x + 0.59f) + 0.14f), 0.0f, 1.0f);
}

float encode(float linear) { return std::clamp(srgbEncode(linear), 0.0f, 1.0f); }

}  // namespace

std::array<float, 3> tonemapRgb(float r, float g, float b, double exposure, Tonemap op) {
    const float scale = float(std::exp2(exposure));
    r = finiteOrZero(r) * scale;
    g = finiteOrZero(g) * scale;
    b = finiteOrZero(b) * scale;
    switch (op) {
    case Tonemap::Srgb:
        return {encode(r), encode(g), encode(b)};
    case Tonemap::Reinhard: {
        // Eq. 3 of Reinhard et al. 2002 on luminance; the channels keep their ratios (negative luminance: black).
        const float l = luminance(r, g, b);
        if (!(l > 0.0f)) return {0.0f, 0.0f, 0.0f};
        const float k = 1.0f / (1.0f + l);
        return {encode(r * k), encode(g * k), encode(b * k)};
    }
    case Tonemap::Aces:
        return {encode(acesFit(std::max(r, 0.0f))), encode(acesFit(std::max(g, 0.0f))),
                encode(acesFit(std::max(b, 0.0f)))};
    case Tonemap::FalseColour: {
        const float l = luminance(r, g, b);
        const double t = l > 0.0f ? (std::log2(double(l)) - kFalseColourMinEv) / (kFalseColourMaxEv - kFalseColourMinEv)
                                  : 0.0;
        const Rgb c = viridis(std::clamp(t, 0.0, 1.0));
        return {encode(float(c.r)), encode(float(c.g)), encode(float(c.b))};
    }
    }
    return {0.0f, 0.0f, 0.0f};
}

}  // namespace tyndall
