#include "tyndall/image/metrics.h"

#include "tyndall/image/colour_map.h"

#include "tyndall/core/error.h"
#include "tyndall/core/text.h"
#include "tyndall/image/image_io.h"

#include <algorithm>
#include <array>
#include <charconv>
#include <cmath>
#include <cstddef>
#include <iterator>
#include <limits>
#include <string>
#include <vector>

namespace tyndall {

namespace {

constexpr double kEpsilon = 0.01;  // the 0.01 in the relMSE, MAPE and relative-difference denominators
constexpr double kInfinity = std::numeric_limits<double>::infinity();

struct RgbChannels {
    int r = -1, g = -1, b = -1;
    int operator[](int k) const { return k == 0 ? r : (k == 1 ? g : b); }
};

RgbChannels rgbChannels(const Image& image, const std::string& role) {
    const RgbChannels channels{image.channelIndex("R"), image.channelIndex("G"), image.channelIndex("B")};
    for (int k = 0; k < 3; ++k) {
        if (channels[k] < 0) {
            throw InputError(InputLocation{.field = role}, std::string("has no channel \"") + "RGB"[k] + "\"");
        }
    }
    return channels;
}

std::string sizeString(const Image& image) {
    return std::to_string(image.width()) + "x" + std::to_string(image.height());
}

void checkSameSize(const Image& image, const Image& reference) {
    if (image.width() != reference.width() || image.height() != reference.height()) {
        throw InputError("image size " + sizeString(image) + " differs from reference size " + sizeString(reference));
    }
}

// JSON has no infinity or NaN: those are written as the strings "inf", "-inf" and "nan".
nlohmann::json jsonNumber(double value) {
    if (std::isfinite(value)) return value;
    return formatNumber(value);
}

// RFC 4180: quote a field holding a comma, a quote or a line break, doubling the quotes.
std::string csvField(const std::string& text) {
    if (text.find_first_of(",\"\r\n") == std::string::npos) return text;
    std::string quoted = "\"";
    for (char c : text) {
        if (c == '"') quoted += '"';
        quoted += c;
    }
    return quoted + "\"";
}

// The region's pixels [x0, x1) x [y0, y1), clipped to the image.
struct PixelRange {
    int x0 = 0, y0 = 0, x1 = 0, y1 = 0;
    long count() const { return static_cast<long>(x1 - x0) * (y1 - y0); }
};

PixelRange clipRegion(const Region& region, int width, int height) {
    if (region.width < 0 || region.height < 0) {
        throw InputError(
            InputLocation{.field = "region"},
            "width and height must be >= 0, got " + std::to_string(region.width) + "x" + std::to_string(region.height));
    }
    if (region.width == 0 || region.height == 0) return {0, 0, width, height};
    const auto clip = [](long v, int size) { return static_cast<int>(std::clamp(v, 0L, static_cast<long>(size))); };
    PixelRange range{clip(region.x, width), clip(region.y, height),
                     clip(static_cast<long>(region.x) + region.width, width),
                     clip(static_cast<long>(region.y) + region.height, height)};
    if (range.x1 <= range.x0 || range.y1 <= range.y0) {
        throw InputError(InputLocation{.field = "region"},
                         "(" + std::to_string(region.x) + ", " + std::to_string(region.y) + ") size " +
                             std::to_string(region.width) + "x" + std::to_string(region.height) + " lies outside the " +
                             std::to_string(width) + "x" + std::to_string(height) + " image");
    }
    return range;
}

double luminance(const Image& image, const RgbChannels& c, int x, int y) {
    return 0.2126 * image.at(x, y, c.r) + 0.7152 * image.at(x, y, c.g) + 0.0722 * image.at(x, y, c.b);
}

constexpr const char* kCsvColumns[] = {"name", "rmse",       "relMSE", "mape",
                                       "psnr", "energyBias", "pixels", "referenceNoiseRelMSE"};

}  // namespace

Metrics computeMetrics(const Image& image, const Image& reference, double exposure, Region region) {
    checkSameSize(image, reference);
    const RgbChannels a = rgbChannels(image, "image");
    const RgbChannels r = rgbChannels(reference, "reference");
    if (!std::isfinite(exposure)) {
        throw InputError(InputLocation{.field = "exposure"}, "must be finite, got " + formatNumber(exposure));
    }
    const PixelRange range = clipRegion(region, image.width(), image.height());

    const RgbChannels variance{reference.channelIndex("variance.R"), reference.channelIndex("variance.G"),
                               reference.channelIndex("variance.B")};
    const bool hasVariance = variance.r >= 0 && variance.g >= 0 && variance.b >= 0;

    double sumSquared = 0.0, sumRelSquared = 0.0, sumRelAbs = 0.0, sumImage = 0.0, sumReference = 0.0;
    double sumDisplaySquared = 0.0, sumNoise = 0.0;
    for (int y = range.y0; y < range.y1; ++y) {
        for (int x = range.x0; x < range.x1; ++x) {
            for (int k = 0; k < 3; ++k) {
                const float av = image.at(x, y, a[k]);
                const float rv = reference.at(x, y, r[k]);
                const double e = static_cast<double>(av) - rv;
                const double r2 = static_cast<double>(rv) * rv;
                sumSquared += e * e;
                sumRelSquared += e * e / (r2 + kEpsilon);
                sumRelAbs += std::abs(e) / (rv + kEpsilon);
                sumImage += av;
                sumReference += rv;
                const double display = static_cast<double>(tonemap(av, exposure)) - tonemap(rv, exposure);
                sumDisplaySquared += display * display;
                if (hasVariance) sumNoise += reference.at(x, y, variance[k]) / (r2 + kEpsilon);
            }
        }
    }

    Metrics m;
    m.pixels = range.count();
    const double n = 3.0 * static_cast<double>(m.pixels);
    m.rmse = std::sqrt(sumSquared / n);
    m.relMSE = sumRelSquared / n;
    m.mape = 100.0 * sumRelAbs / n;
    const double displayMSE = sumDisplaySquared / n;
    m.psnr = displayMSE == 0.0 ? kInfinity : 10.0 * std::log10(1.0 / displayMSE);
    const double meanImage = sumImage / n, meanReference = sumReference / n;
    if (meanReference != 0.0) {
        m.energyBias = 100.0 * (meanImage - meanReference) / meanReference;
    } else {
        // No energy in the reference: any energy in the image is an infinite excess (or deficit, if negative).
        m.energyBias = meanImage == 0.0 ? 0.0 : std::copysign(kInfinity, meanImage);
    }
    if (hasVariance) m.referenceNoiseRelMSE = sumNoise / n;
    return m;
}

nlohmann::json metricsToJson(const Metrics& m) {
    nlohmann::json json = nlohmann::json::object();
    json["rmse"] = jsonNumber(m.rmse);
    json["relMSE"] = jsonNumber(m.relMSE);
    json["mape"] = jsonNumber(m.mape);
    json["psnr"] = jsonNumber(m.psnr);
    json["energyBias"] = jsonNumber(m.energyBias);
    json["pixels"] = m.pixels;
    if (m.referenceNoiseRelMSE) json["referenceNoiseRelMSE"] = jsonNumber(*m.referenceNoiseRelMSE);
    return json;
}

std::string metricsCsvHeader() {
    std::string header;
    for (const char* column : kCsvColumns)
        header += (header.empty() ? "" : ",") + std::string(column);
    return header;
}

std::string metricsCsvRow(const std::string& name, const Metrics& m) {
    const std::string fields[] = {
        csvField(name),
        formatNumber(m.rmse),
        formatNumber(m.relMSE),
        formatNumber(m.mape),
        formatNumber(m.psnr),
        formatNumber(m.energyBias),
        std::to_string(m.pixels),
        m.referenceNoiseRelMSE ? formatNumber(*m.referenceNoiseRelMSE) : std::string(),  // empty when unknown
    };
    static_assert(std::size(fields) == std::size(kCsvColumns));
    std::string row;
    for (std::size_t i = 0; i < std::size(fields); ++i)
        row += (i == 0 ? "" : ",") + fields[i];
    return row;
}

Image differenceImage(const Image& image, const Image& reference, DifferenceKind kind, double scale) {
    if (!(scale > 0.0) || !std::isfinite(scale)) {
        throw InputError(InputLocation{.field = "scale"}, "must be > 0 and finite, got " + formatNumber(scale));
    }
    checkSameSize(image, reference);
    const RgbChannels a = rgbChannels(image, "image");
    const RgbChannels r = rgbChannels(reference, "reference");

    Image out = Image::rgb(image.width(), image.height());
    for (int y = 0; y < image.height(); ++y) {
        for (int x = 0; x < image.width(); ++x) {
            const double Ya = luminance(image, a, x, y);
            const double Yr = luminance(reference, r, x, y);
            const double d = Ya - Yr;
            Rgb colour(0.0);  // black, in neither map, marks a NaN difference
            switch (kind) {
                case DifferenceKind::Signed:
                    if (!std::isnan(d)) colour = diverging(0.5 + 0.5 * std::clamp(d / scale, -1.0, 1.0));
                    break;
                case DifferenceKind::Absolute:
                    if (!std::isnan(d)) colour = viridis(std::abs(d) / scale);
                    break;
                case DifferenceKind::Relative: {
                    const double t = std::abs(d) / (Yr + kEpsilon) / scale;
                    if (!std::isnan(t)) colour = viridis(t);
                    break;
                }
            }
            for (int c = 0; c < 3; ++c)
                out.at(x, y, c) = static_cast<float>(colour[c]);
        }
    }

    out.metadata["difference.kind"] = kind == DifferenceKind::Signed     ? "signed"
                                      : kind == DifferenceKind::Absolute ? "absolute"
                                                                         : "relative";
    out.metadata["difference.scale"] = formatNumber(scale);
    out.metadata["difference.colourMap"] = kind == DifferenceKind::Signed ? "RdBu_r" : "viridis";
    return out;
}

}  // namespace tyndall
