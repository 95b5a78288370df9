// Tests of the error metrics, the false-colour difference images and their colour maps, against values computed by
// hand on images of a few pixels.
#include "tyndall/core/error.h"
#include "tyndall/image/colour_map.h"
#include "tyndall/image/image_io.h"
#include "tyndall/image/metrics.h"

#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <filesystem>
#include <functional>
#include <limits>
#include <string>
#include <vector>

namespace tyndall {
namespace {

namespace fs = std::filesystem;

constexpr double kInf = std::numeric_limits<double>::infinity();

// An RGB image from its pixels, row-major from the top-left.
Image rgbImage(int width, int height, const std::vector<std::array<float, 3>>& pixels) {
    Image image = Image::rgb(width, height);
    for (int i = 0; i < width * height; ++i) {
        for (int c = 0; c < 3; ++c)
            image.at(i % width, i / width, c) = pixels.at(i)[c];
    }
    return image;
}

Image greyImage(int width, int height, const std::vector<float>& values) {
    std::vector<std::array<float, 3>> pixels;
    for (float v : values)
        pixels.push_back({v, v, v});
    return rgbImage(width, height, pixels);
}

std::array<float, 3> pixel(const Image& image, int x, int y) {
    return {image.at(x, y, 0), image.at(x, y, 1), image.at(x, y, 2)};
}

// A linear colour as the 0-255 sRGB values a PNG would hold (unrounded).
std::array<double, 3> srgb255(const Rgb& linear) {
    std::array<double, 3> out{};
    for (int c = 0; c < 3; ++c)
        out[c] = 255.0 * srgbEncode(static_cast<float>(linear[c]));
    return out;
}

void expectSrgb(const Rgb& linear, std::array<double, 3> expected, double tolerance = 0.5) {
    const std::array<double, 3> actual = srgb255(linear);
    for (int c = 0; c < 3; ++c)
        EXPECT_NEAR(actual[c], expected[c], tolerance) << "channel " << c;
}

std::string thrownMessage(const std::function<void()>& f) {
    try {
        f();
    } catch (const InputError& e) {
        return e.what();
    }
    ADD_FAILURE() << "expected InputError";
    return {};
}

// ---------------------------------------------------------------------------------------------------------------------
// Metrics

TEST(Metrics, HandComputedValuesOnTwoPixels) {
    // r = (1, 2, 0), (0, 0.5, 1);  a = (1.5, 2, 0), (0, 0.25, 1.5);  e = a - r = (0.5, 0, 0), (0, -0.25, 0.5).
    const Image reference = rgbImage(2, 1, {{1.0f, 2.0f, 0.0f}, {0.0f, 0.5f, 1.0f}});
    const Image image = rgbImage(2, 1, {{1.5f, 2.0f, 0.0f}, {0.0f, 0.25f, 1.5f}});
    const Metrics m = computeMetrics(image, reference);

    // sum e^2 = 0.25 + 0.0625 + 0.25 = 0.5625 over 6 values: MSE = 0.09375, RMSE = 0.306186.
    EXPECT_NEAR(m.rmse, 0.3061862178, 1e-9);
    // e^2 / (r^2 + 0.01): 0.25 / 1.01 = 0.2475248, 0.0625 / 0.26 = 0.2403846, 0.25 / 1.01 = 0.2475248 (others 0);
    // sum 0.7354342 / 6 = 0.1225724.
    EXPECT_NEAR(m.relMSE, 0.1225723534, 1e-9);
    // |e| / (r + 0.01): 0.5 / 1.01 = 0.4950495, 0.25 / 0.51 = 0.4901961, 0.5 / 1.01 = 0.4950495;
    // sum 1.4802951 / 6 * 100 = 24.67158 %.
    EXPECT_NEAR(m.mape, 24.671584806, 1e-7);
    // mean(a) = 5.25 / 6 = 0.875, mean(r) = 4.5 / 6 = 0.75: bias = 100 * 0.125 / 0.75 = 16.6667 %.
    EXPECT_NEAR(m.energyBias, 100.0 / 6.0, 1e-9);
    // Tonemapped at exposure 0 (values >= 1 clamp to 1): the only display difference is
    // srgb(0.25) - srgb(0.5) = 0.5370987 - 0.7353570 = -0.1982583; MSE = 0.0393063 / 6 = 0.00655106;
    // PSNR = 10 log10(1 / 0.00655106) = 21.8369 dB.
    EXPECT_NEAR(m.psnr, 21.836887, 1e-4);
    EXPECT_EQ(m.pixels, 2);
    EXPECT_FALSE(m.referenceNoiseRelMSE.has_value());
}

TEST(Metrics, PsnrUsesTheExposure) {
    // a = 0.5, r = 0.25 everywhere; exposure 1 doubles both: srgb(1) = 1 and srgb(0.5) = 0.7353570;
    // MSE = 0.2646430^2 = 0.0700359, PSNR = 10 log10(1 / 0.0700359) = 11.5468 dB.
    const Image image = greyImage(2, 1, {0.5f, 0.5f});
    const Image reference = greyImage(2, 1, {0.25f, 0.25f});
    EXPECT_NEAR(computeMetrics(image, reference, 1.0).psnr, 11.546791, 1e-4);
    // At exposure 2 both clamp to white: the display images are identical.
    EXPECT_EQ(computeMetrics(image, reference, 2.0).psnr, kInf);
}

TEST(Metrics, IdenticalImagesGiveInfinitePsnrAndZeros) {
    const Image image =
        rgbImage(2, 2, {{0.1f, 0.2f, 0.3f}, {1.0f, 2.0f, 3.0f}, {0.0f, 0.0f, 0.0f}, {5.0f, 0.5f, 0.05f}});
    const Metrics m = computeMetrics(image, image);
    EXPECT_EQ(m.rmse, 0.0);
    EXPECT_EQ(m.relMSE, 0.0);
    EXPECT_EQ(m.mape, 0.0);
    EXPECT_EQ(m.energyBias, 0.0);
    EXPECT_EQ(m.psnr, kInf);
    EXPECT_EQ(m.pixels, 4);
    EXPECT_EQ(metricsToJson(m)["psnr"], "inf");
}

TEST(Metrics, EnergyBiasAgainstABlackReference) {
    const Image black = greyImage(2, 1, {0.0f, 0.0f});
    EXPECT_EQ(computeMetrics(black, black).energyBias, 0.0);
    EXPECT_EQ(computeMetrics(greyImage(2, 1, {0.0f, 0.5f}), black).energyBias, kInf);
}

TEST(Metrics, RegionSelectsItsPixels) {
    // r = 1 everywhere; a = 5 in the left column, 2 at (1, 0) and 1.5 at (1, 1).
    const Image reference = greyImage(2, 2, {1.0f, 1.0f, 1.0f, 1.0f});
    const Image image = greyImage(2, 2, {5.0f, 2.0f, 5.0f, 1.5f});
    // The right column: e = 1 and 0.5, MSE = (1 + 0.25) / 2 = 0.625, RMSE = 0.790569;
    // relMSE = 0.625 / 1.01 = 0.618812.
    const Metrics m = computeMetrics(image, reference, 0.0, Region{1, 0, 1, 2});
    EXPECT_EQ(m.pixels, 2);
    EXPECT_NEAR(m.rmse, 0.7905694150, 1e-9);
    EXPECT_NEAR(m.relMSE, 0.625 / 1.01, 1e-9);
    // A width or height of 0 means the whole image.
    EXPECT_EQ(computeMetrics(image, reference, 0.0, Region{1, 1, 0, 0}).pixels, 4);
}

TEST(Metrics, RegionPartlyOutsideIsClipped) {
    const Image reference = greyImage(2, 2, {1.0f, 1.0f, 1.0f, 1.0f});
    const Image image = greyImage(2, 2, {5.0f, 2.0f, 5.0f, 1.5f});
    // [1, 11) x [1, 11) clips to the pixel (1, 1): e = 0.5.
    const Metrics bottomRight = computeMetrics(image, reference, 0.0, Region{1, 1, 10, 10});
    EXPECT_EQ(bottomRight.pixels, 1);
    EXPECT_NEAR(bottomRight.rmse, 0.5, 1e-12);
    // [-5, 1) x [-5, 1) clips to the pixel (0, 0): e = 4.
    const Metrics topLeft = computeMetrics(image, reference, 0.0, Region{-5, -5, 6, 6});
    EXPECT_EQ(topLeft.pixels, 1);
    EXPECT_NEAR(topLeft.rmse, 4.0, 1e-12);
}

TEST(Metrics, RegionOutsideTheImageOrNegativeThrows) {
    const Image image = greyImage(2, 2, {1.0f, 1.0f, 1.0f, 1.0f});
    for (const Region& region : {Region{2, 0, 1, 1}, Region{0, -3, 2, 3}, Region{-1, 0, 1, 1}, Region{0, 0, -1, 1}}) {
        const std::string message = thrownMessage([&] { computeMetrics(image, image, 0.0, region); });
        EXPECT_NE(message.find("region"), std::string::npos) << message;
    }
}

TEST(Metrics, MismatchedSizesThrowNamingBoth) {
    const std::string message = thrownMessage([] {
        computeMetrics(greyImage(2, 1, {0.0f, 0.0f}), greyImage(2, 2, {0.f, 0.f, 0.f, 0.f}));
    });
    EXPECT_NE(message.find("2x1"), std::string::npos) << message;
    EXPECT_NE(message.find("2x2"), std::string::npos) << message;
}

TEST(Metrics, MissingRgbThrows) {
    const Image luminance(2, 1, {"Y"});
    const Image rgb = Image::rgb(2, 1);
    EXPECT_THROW(computeMetrics(luminance, rgb), InputError);
    EXPECT_THROW(computeMetrics(rgb, luminance), InputError);
}

TEST(Metrics, ReferenceNoiseRelMSEFromVarianceChannels) {
    // r = 1 at (0, 0) with variance 0.0202, r = 0 at (1, 0) with variance 0.0001, in every channel:
    // var / (r^2 + 0.01) = 0.0202 / 1.01 = 0.02 and 0.0001 / 0.01 = 0.01, mean 0.015.
    Image reference = greyImage(2, 1, {1.0f, 0.0f});
    const int v = reference.addChannels({"variance.R", "variance.G", "variance.B"});
    for (int c = 0; c < 3; ++c) {
        reference.at(0, 0, v + c) = 0.0202f;
        reference.at(1, 0, v + c) = 0.0001f;
    }
    const Metrics m = computeMetrics(greyImage(2, 1, {1.0f, 0.0f}), reference);
    ASSERT_TRUE(m.referenceNoiseRelMSE.has_value());
    EXPECT_NEAR(*m.referenceNoiseRelMSE, 0.015, 1e-8);
    EXPECT_NEAR(metricsToJson(m)["referenceNoiseRelMSE"].get<double>(), 0.015, 1e-8);
}

TEST(Metrics, JsonAndCsv) {
    Metrics m;
    m.rmse = 0.5;
    m.relMSE = 0.25;
    m.mape = 12.5;
    m.psnr = kInf;
    m.energyBias = -3.0;
    m.pixels = 42;
    const nlohmann::json json = metricsToJson(m);
    EXPECT_EQ(json["rmse"], 0.5);
    EXPECT_EQ(json["relMSE"], 0.25);
    EXPECT_EQ(json["mape"], 12.5);
    EXPECT_EQ(json["psnr"], "inf");
    EXPECT_EQ(json["energyBias"], -3.0);
    EXPECT_EQ(json["pixels"], 42);
    EXPECT_FALSE(json.contains("referenceNoiseRelMSE"));
    EXPECT_TRUE(nlohmann::json::accept(json.dump()));

    EXPECT_EQ(metricsCsvHeader(), "name,rmse,relMSE,mape,psnr,energyBias,pixels,referenceNoiseRelMSE");
    EXPECT_EQ(metricsCsvRow("ltsd", m), "ltsd,0.5,0.25,12.5,inf,-3,42,");
    m.referenceNoiseRelMSE = 0.001;
    EXPECT_EQ(metricsCsvRow("ltsd, \"fast\"", m), "\"ltsd, \"\"fast\"\"\",0.5,0.25,12.5,inf,-3,42,0.001");
}

// ---------------------------------------------------------------------------------------------------------------------
// Difference images

TEST(DifferenceImage, SignedZeroIsTheWhiteCentre) {
    const Image image = rgbImage(2, 1, {{0.3f, 0.6f, 0.9f}, {0.0f, 0.0f, 0.0f}});
    const Image difference = differenceImage(image, image, DifferenceKind::Signed, 0.1);
    for (int x = 0; x < 2; ++x) {
        const auto p = pixel(difference, x, 0);
        for (int c = 0; c < 3; ++c)
            EXPECT_NEAR(p[c], diverging(0.5)[c], 1e-7);
        expectSrgb(Rgb(p[0], p[1], p[2]), {247.0, 247.0, 247.0});  // RdBu's centre, #f7f7f7
    }
}

TEST(DifferenceImage, SignedEndsAreRedAndBlue) {
    // Grey pixels, so that the luminance difference is the value difference (the Rec.709 weights sum to 1).
    const Image reference = greyImage(4, 1, {0.5f, 0.5f, 0.5f, 0.5f});
    const Image image = greyImage(4, 1, {0.75f, 0.25f, 2.0f, 0.0f});  // +scale, -scale, beyond +scale, beyond -scale
    const Image difference = differenceImage(image, reference, DifferenceKind::Signed, 0.25);
    const Rgb red = diverging(1.0), blue = diverging(0.0);
    for (int c = 0; c < 3; ++c) {
        EXPECT_NEAR(difference.at(0, 0, c), red[c], 1e-6);
        EXPECT_NEAR(difference.at(1, 0, c), blue[c], 1e-6);
        EXPECT_NEAR(difference.at(2, 0, c), red[c], 1e-6);
        EXPECT_NEAR(difference.at(3, 0, c), blue[c], 1e-6);
    }
    EXPECT_GT(red.r, 4.0 * red.g);
    EXPECT_GT(red.r, 2.0 * red.b);
    EXPECT_GT(blue.b, 2.0 * blue.r);
    EXPECT_GT(blue.b, blue.g);
}

TEST(DifferenceImage, AbsoluteUsesViridisEndpoints) {
    const Image reference = greyImage(3, 1, {1.0f, 1.0f, 1.0f});
    const Image image = greyImage(3, 1, {1.0f, 3.0f, -2.0f});  // |d| = 0, 2 (= scale), 3 (beyond)
    const Image difference = differenceImage(image, reference, DifferenceKind::Absolute, 2.0);
    for (int c = 0; c < 3; ++c) {
        EXPECT_NEAR(difference.at(0, 0, c), viridis(0.0)[c], 1e-7);
        EXPECT_NEAR(difference.at(1, 0, c), viridis(1.0)[c], 1e-7);
        EXPECT_NEAR(difference.at(2, 0, c), viridis(1.0)[c], 1e-7);
    }
}

TEST(DifferenceImage, AbsoluteIsOfRec709Luminance) {
    // a = pure green 1, r = black: Y difference 0.7152, at scale 1 viridis(0.7152).
    const Image difference = differenceImage(rgbImage(1, 1, {{0.0f, 1.0f, 0.0f}}), rgbImage(1, 1, {{0.f, 0.f, 0.f}}),
                                             DifferenceKind::Absolute, 1.0);
    for (int c = 0; c < 3; ++c)
        EXPECT_NEAR(difference.at(0, 0, c), viridis(0.7152)[c], 1e-6);
}

TEST(DifferenceImage, RelativeDividesByTheReference) {
    // |1.49 - 0.99| / (0.99 + 0.01) = 0.5; at scale 2 that is t = 0.25.
    const Image difference =
        differenceImage(greyImage(1, 1, {1.49f}), greyImage(1, 1, {0.99f}), DifferenceKind::Relative, 2.0);
    for (int c = 0; c < 3; ++c)
        EXPECT_NEAR(difference.at(0, 0, c), viridis(0.25)[c], 1e-5);
}

TEST(DifferenceImage, FixedScaleNotPerImageMinMax) {
    // The same difference (0.1) at pixel 0 must get the same colour whatever the other pixel's difference is.
    const Image reference = greyImage(2, 1, {1.0f, 1.0f});
    for (DifferenceKind kind : {DifferenceKind::Signed, DifferenceKind::Absolute, DifferenceKind::Relative}) {
        const Image small = differenceImage(greyImage(2, 1, {1.1f, 1.2f}), reference, kind, 1.0);
        const Image large = differenceImage(greyImage(2, 1, {1.1f, 50.0f}), reference, kind, 1.0);
        EXPECT_EQ(pixel(small, 0, 0), pixel(large, 0, 0));
        EXPECT_NE(pixel(small, 1, 0), pixel(large, 1, 0));
    }
}

TEST(DifferenceImage, MetadataNamesKindScaleAndColourMap) {
    const Image image = greyImage(1, 1, {0.5f});
    const Image signedDifference = differenceImage(image, image, DifferenceKind::Signed, 0.5);
    EXPECT_EQ(signedDifference.metadata.at("difference.kind"), "signed");
    EXPECT_EQ(signedDifference.metadata.at("difference.scale"), "0.5");
    EXPECT_EQ(signedDifference.metadata.at("difference.colourMap"), "RdBu_r");
    const Image relative = differenceImage(image, image, DifferenceKind::Relative, 0.25);
    EXPECT_EQ(relative.metadata.at("difference.kind"), "relative");
    EXPECT_EQ(relative.metadata.at("difference.scale"), "0.25");
    EXPECT_EQ(relative.metadata.at("difference.colourMap"), "viridis");
}

TEST(DifferenceImage, RejectsBadScalesAndSizes) {
    const Image image = greyImage(1, 1, {0.5f});
    for (double scale : {0.0, -1.0, std::numeric_limits<double>::quiet_NaN(), kInf}) {
        const std::string message =
            thrownMessage([&] { differenceImage(image, image, DifferenceKind::Signed, scale); });
        EXPECT_NE(message.find("scale"), std::string::npos) << message;
    }
    EXPECT_THROW(differenceImage(image, greyImage(2, 1, {0.f, 0.f}), DifferenceKind::Absolute, 1.0), InputError);
}

TEST(DifferenceImage, NanDifferenceIsBlack) {
    const Image image = greyImage(1, 1, {std::numeric_limits<float>::quiet_NaN()});
    const Image difference = differenceImage(image, greyImage(1, 1, {0.5f}), DifferenceKind::Signed, 1.0);
    EXPECT_EQ(pixel(difference, 0, 0), (std::array<float, 3>{0.0f, 0.0f, 0.0f}));
}

// ---------------------------------------------------------------------------------------------------------------------
// Colour maps

TEST(ColourMap, ViridisMatchesThePublishedColours) {
    expectSrgb(viridis(0.0), {68.0, 1.0, 84.0});           // #440154
    expectSrgb(viridis(1.0), {253.0, 231.0, 37.0}, 0.75);  // #fde725
    expectSrgb(viridis(0.5), {33.0, 145.0, 140.0}, 1.0);   // #21918c
}

TEST(ColourMap, MagmaMatchesThePublishedColours) {
    expectSrgb(magma(0.0), {0.0, 0.0, 4.0}, 0.5);        // #000004
    expectSrgb(magma(1.0), {252.0, 253.0, 191.0}, 0.5);  // #fcfdbf
    expectSrgb(magma(0.5), {182.0, 55.0, 121.0}, 0.5);   // between entries 127 and 128 (#b53679, #b73779)
}

TEST(ColourMap, DivergingRunsBlueWhiteRed) {
    expectSrgb(diverging(0.0), {5.0, 48.0, 97.0});      // #053061
    expectSrgb(diverging(0.5), {247.0, 247.0, 247.0});  // #f7f7f7
    expectSrgb(diverging(1.0), {103.0, 0.0, 31.0});     // #67001f
}

TEST(ColourMap, ClampsTAndTreatsNanAsZero) {
    EXPECT_EQ(viridis(-1.0), viridis(0.0));
    EXPECT_EQ(viridis(7.0), viridis(1.0));
    EXPECT_EQ(viridis(std::numeric_limits<double>::quiet_NaN()), viridis(0.0));
    EXPECT_EQ(diverging(-1.0), diverging(0.0));
    EXPECT_EQ(diverging(2.0), diverging(1.0));
}

TEST(ColourMap, PngOfADifferenceImageHoldsTheMapsSrgbColours) {
    const fs::path dir = fs::path(TYNDALL_TEST_TMP) / "metrics";
    fs::create_directories(dir);
    const fs::path path = dir / "colour_map.png";

    Image image = Image::rgb(3, 1);
    const Rgb colours[3] = {viridis(0.0), viridis(1.0), diverging(0.5)};
    for (int x = 0; x < 3; ++x) {
        for (int c = 0; c < 3; ++c)
            image.at(x, 0, c) = static_cast<float>(colours[x][c]);
    }
    writeImage(image, path.string());
    const Image read = readImage(path.string());
    const int expected[3][3] = {{68, 1, 84}, {253, 231, 37}, {247, 247, 247}};
    for (int x = 0; x < 3; ++x) {
        for (int c = 0; c < 3; ++c)
            EXPECT_EQ(std::lround(read.at(x, 0, c) * 255.0f), expected[x][c]);
    }
}

}  // namespace
}  // namespace tyndall
