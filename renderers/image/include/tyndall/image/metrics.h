// Image error metrics against a reference (docs/conventions.md, "Errors"). With e = a - r over RGB:
//   RMSE   = sqrt(mean(e^2))
//   relMSE = mean(e^2 / (r^2 + 0.01))
//   MAPE   = 100 * mean(|e| / (r + 0.01))         (percent)
//   PSNR   = 10 log10(1 / MSE) on images tonemapped with the view's exposure, sRGB-encoded and clamped to [0, 1] (dB)
//   bias   = 100 * (mean(a) - mean(r)) / mean(r)  (percent, "energy bias")
#pragma once

#include "tyndall/core/scene.h"
#include "tyndall/image/image.h"

#include <nlohmann/json.hpp>

#include <optional>
#include <string>

namespace tyndall {

struct Region {
    int x = 0, y = 0, width = 0, height = 0;  // pixels; width or height 0 means the whole image
};

struct Metrics {
    double rmse = 0.0;
    double relMSE = 0.0;
    double mape = 0.0;
    double psnr = 0.0;        // +inf when identical
    double energyBias = 0.0;  // percent; 0 when the reference's mean is 0 and the image's too
    long pixels = 0;
    // The reference's own noise as a relMSE, from its "variance.R/G/B" channels (variance of the pixel mean), when it
    // has them: mean(var / (r^2 + 0.01)). A technique whose relMSE is near this cannot be told from the reference.
    std::optional<double> referenceNoiseRelMSE;
};

// Throws InputError when the sizes differ or either image lacks R, G, B.
Metrics computeMetrics(const Image& image, const Image& reference, double exposure = 0.0, Region region = {});

nlohmann::json metricsToJson(const Metrics& m);
std::string metricsCsvHeader();
std::string metricsCsvRow(const std::string& name, const Metrics& m);

// False-colour difference images on one fixed scale (never per-image min-max):
//   Signed:   a - r in a diverging map, 0 at the centre, +-scale at the ends
//   Absolute: |a - r| in viridis over [0, scale]
//   Relative: |a - r| / (r + 0.01) in viridis over [0, scale]
// Differences are of luminance (Rec.709 weights).
enum class DifferenceKind { Signed, Absolute, Relative };
Image differenceImage(const Image& image, const Image& reference, DifferenceKind kind, double scale);

}  // namespace tyndall
