// FLIP, the perceptual difference evaluator for alternating images (Andersson et al., "FLIP: A Difference Evaluator for
// Alternating Images", HPG 2020) and its HDR extension (Andersson et al., "Visualizing Errors in Rendered High Dynamic
// Range Images", EG 2021), written from the papers' equations and constants (docs/flip.md derives each step).
#pragma once

#include "tyndall/image/image.h"

#include <string>
#include <vector>

namespace tyndall {

// Pixels per degree of visual angle of an observer at `distance` from a monitor `width` wide with `resolution` pixels
// across: distance (resolution / width) pi / 180. The default, 0.7 m from a 0.7 m wide 3840-pixel monitor, is 67.02.
double flipPixelsPerDegree(double distance = 0.7, double resolution = 3840.0, double width = 0.7);

// LDR-FLIP of two images of display-encoded sRGB values in [0, 1] (channels R, G, B): per pixel an error in [0, 1],
// row-major. Throws InputError for images of different sizes or without R, G, B.
std::vector<float> ldrFlip(const Image& reference, const Image& test, double pixelsPerDegree = flipPixelsPerDegree());

// The cube root the colour pipeline takes (CIELAB's f), for t > 0: relative error below 1e-11 (Flip.CubeRoot...).
double flipCubeRoot(double t);

// The tone mappers of HDR-FLIP, each a rational polynomial (k0 x^2 + k1 x + k2) / (k3 x^2 + k4 x + k5) of the exposed
// linear value, clamped to [0, 1].
enum class FlipToneMapper { Aces, Hable, Reinhard };
FlipToneMapper flipToneMapperFromName(const std::string& name);  // "aces", "hable", "reinhard"; InputError else
double flipToneMap(FlipToneMapper toneMapper, double x);
// The exposed value at which the tone mapper reaches t (the knee of the exposure range, t = 0.85).
double flipToneMapperInverse(FlipToneMapper toneMapper, double t);

struct HdrFlipSettings {
    double pixelsPerDegree = flipPixelsPerDegree();
    FlipToneMapper toneMapper = FlipToneMapper::Aces;
    bool automaticExposures = true;  // the range from the reference (below); else startExposure and stopExposure
    double startExposure = 0.0;
    double stopExposure = 0.0;
    int exposures = 0;  // 0: max(2, ceil(stop - start))
    // 0: TBB's threads, the work isolated (a caller waiting on it runs none of another loop's tasks meanwhile);
    // 1: the calling thread alone (the studio's niced background pool, beside CPU renders).
    int threads = 0;
};

struct HdrFlipResult {
    std::vector<float> error;        // per pixel, row-major, in [0, 1]: the maximum of LDR-FLIP over the exposures
    std::vector<int> exposureIndex;  // per pixel, the exposure that gave it
    double startExposure = 0.0, stopExposure = 0.0;
    int exposures = 0;
};

// The automatic exposure range: start = log2(x_max / Y_max), stop = log2(x_min / Y_median), with Y the reference's
// luminance (Rec. 709 weights) and x_max = x_min the tone mapper's value at 0.85. Without any positive luminance the
// range is [0, 0]; with a median of 0 the median of the positive luminances stands for it.
void flipExposureRange(const Image& reference, FlipToneMapper toneMapper, double& start, double& stop);

// HDR-FLIP of two linear images (R, G, B; negative values count as 0): for each exposure c of the range, both images
// are scaled by 2^c, tone mapped, encoded as sRGB and compared by LDR-FLIP; the error is the maximum over exposures.
HdrFlipResult hdrFlip(const Image& reference, const Image& test, const HdrFlipSettings& settings = {});

// The summary FLIP's papers report: the mean, and the quartiles and median of the errors weighted by themselves (the
// value below which a fraction p of the total error lies), with the minimum and maximum.
struct FlipStatistics {
    double mean = 0.0, weightedMedian = 0.0, weightedFirstQuartile = 0.0, weightedThirdQuartile = 0.0;
    double minimum = 0.0, maximum = 0.0;
};
FlipStatistics flipStatistics(const std::vector<float>& error);
// The mean error over a rectangle of a map `mapWidth` pixels across (x, y, width, height in pixels, inside the map):
// a region's FLIP, from the map of the whole image (the filters need the region's surroundings).
double flipRegionMean(const std::vector<float>& error, int mapWidth, int x, int y, int width, int height);

// The histogram FLIP's reports plot: `bins` equal bins over [0, 1] (the last one closed), each with its pixel count and
// its share of the summed error (the pixels weighted by their error; the shares sum to 1 unless every error is 0).
struct FlipHistogramBin {
    double low = 0.0, high = 0.0;
    long pixels = 0;
    double weightedShare = 0.0;
};
std::vector<FlipHistogramBin> flipHistogram(const std::vector<float>& error, int bins = 100);

// The error map as FLIP's papers show it: each pixel's error (row-major, width x height) through magma, as linear RGB
// (an sRGB encoding gives magma's published colours): black where the images cannot be told apart, pale yellow at 1.
Image flipColourMap(const std::vector<float>& error, int width, int height);

}  // namespace tyndall
