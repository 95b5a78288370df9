// An edge-aware a-trous wavelet denoiser for Monte Carlo images and for the ratio estimators of Sec. 6 of the LTSD
// paper (000). The idea follows Dammertz et al. 2010 (edge-avoiding a-trous transform: a 5x5 B3-spline kernel whose
// taps are spread 2^i pixels apart at level i, each tap weighted by edge-stopping functions) and Schied et al. 2017
// (SVGF: the colour weight measured in standard deviations of the noise, the variance filtered along). The guides are
// per-pixel depth, normal and a noise-free guide image (the unshadowed render). See docs/denoise.md.
#pragma once

#include "tyndall/image/image.h"

namespace tyndall {

// Per-pixel guides of the same size as the noisy image; any may be null (its weight is then 1).
struct DenoiseGuides {
    const Image* depth = nullptr;   // "Z" or the only channel: distance along the view; non-finite = no surface
    const Image* normal = nullptr;  // "N.X", "N.Y", "N.Z" or exactly three channels; unit, zero = no surface
    const Image* guide = nullptr;   // noise-free, e.g. the unshadowed render: "R", "G", "B" if present, else all
};

// Plain data (docs/denoise.md); every sigma <= 0 turns its weight off.
struct DenoiseSettings {
    int iterations = 5;            // a-trous levels, [0, 12]; level i spaces its 5x5 taps 2^i pixels apart
    float sigmaDepth = 1.0f;       // depth: exp(-|dz| / (sigmaDepth |grad z . offset| + 1e-3 z)), in local slopes
    float normalExponent = 64.0f;  // normal: max(0, n_p . n_q)^normalExponent
    float sigmaGuide = 0.25f;      // guide: exp(-(|g_p - g_q| / max(g_p, g_q) / sigmaGuide)^2), a relative change
    float sigmaColour = 3.0f;      // colour: exp(-d^2 / (2 sigmaColour^2)), d in noise standard deviations
    float minDenominator = 0.0f;   // denoiseRatio: |denominator| <= this after denoising gives ratioFallback
    float ratioFallback = 0.0f;    // denoiseRatio: the ratio there (0: no light; WVDS's raw ratio adds none)
};

// Denoises every channel of `noisy` with one set of weights per level. `variance` (optional, same size) holds the
// variance of each pixel's estimate, in channels "variance.<name>" or "<name>" for each channel of `noisy`; without
// it the noise is estimated per channel from the whole image (a robust, global estimate). Throws InputError naming
// the image and what is wrong (size, missing channel, non-finite value, settings out of range).
Image denoise(const Image& noisy, const Image* variance, const DenoiseGuides& guides, const DenoiseSettings& settings);

// The ratio of Eq. 22-23, LTSD paper (000): numerator and denominator (same size and channels) are filtered with the
// SAME weights, the colour weight measured on their current ratio, and then divided. With denoised = false it is the
// raw per-pixel ratio. `variance` (optional) is the variance of the raw ratio per pixel (for example (r_A - r_B)^2 / 4
// from two halves of the samples), in channels "variance.<name>" or "<name>". Where |denominator| <= minDenominator
// (or the ratio would not be finite) the result is settings.ratioFallback: never NaN or infinite. The result has the
// numerator's channels.
Image denoiseRatio(const Image& numerator, const Image& denominator, const Image* variance, const DenoiseGuides& guides,
                   const DenoiseSettings& settings, bool denoised = true);

}  // namespace tyndall
