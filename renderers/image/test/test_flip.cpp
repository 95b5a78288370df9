// FLIP (issue 35) stage by stage on inputs with known answers: the monitor model, identical images, a flat colour
// difference (no features: the colour pipeline alone, against its closed form), a luminance step's edge response,
// symmetry and range, the tone mappers' knees and the HDR exposure range of an image of known maximum and median.
#include "tyndall/image/flip.h"

#include "tyndall/core/error.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

namespace tyndall {
namespace {

Image flat(int w, int h, float r, float g, float b) {
    Image image(w, h, {"R", "G", "B"});
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            image.at(x, y, 0) = r;
            image.at(x, y, 1) = g;
            image.at(x, y, 2) = b;
        }
    return image;
}

Image noisy(int w, int h, std::uint32_t seed, float amplitude, const Image* base = nullptr) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<float> u(-amplitude, amplitude);
    Image image = base ? *base : flat(w, h, 0.5f, 0.5f, 0.5f);
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x)
            for (int c = 0; c < 3; ++c)
                image.at(x, y, c) = std::clamp(image.at(x, y, c) + u(rng), 0.0f, 1.0f);
    return image;
}

TEST(Flip, PixelsPerDegreeOfTheDefaultMonitor) {
    // 0.7 m from a 0.7 m wide 3840-pixel monitor: 3840 pi / 180.
    EXPECT_NEAR(flipPixelsPerDegree(), 67.0206, 1e-4);
    EXPECT_NEAR(flipPixelsPerDegree(1.0, 1920.0, 0.5), 1920.0 * 2.0 * M_PI / 180.0, 1e-9);
}

TEST(Flip, CubeRootMatchesTheLibrarysToTenDigitsAndMore) {
    // Over the range the colour pipeline uses (XYZ / white of RGB in [0, 1]: 0.0089 to 1.09) and well beyond it.
    double worst = 0.0;
    for (int i = 0; i <= 20000; ++i) {
        const double t = std::pow(10.0, -12.0 + 14.0 * i / 20000.0);
        worst = std::max(worst, std::abs(flipCubeRoot(t) - std::cbrt(t)) / std::cbrt(t));
    }
    EXPECT_LT(worst, 1e-11);
    EXPECT_EQ(flipCubeRoot(1.0), 1.0);
    EXPECT_NEAR(flipCubeRoot(8.0), 2.0, 1e-14);
}

TEST(Flip, IdenticalImagesGiveZeroEverywhere) {
    const Image a = noisy(40, 30, 1u, 0.4f);
    for (float e : ldrFlip(a, a))
        ASSERT_EQ(e, 0.0f);
    Image hdr = a;
    hdr.at(3, 4, 0) = 40.0f;
    for (float e : hdrFlip(hdr, hdr).error)
        ASSERT_EQ(e, 0.0f);
}

// Flat images have no features and filter to themselves: the error is the colour pipeline's alone. For greys the
// Hunt-adjusted a and b vanish, HyAB is |L*_1 - L*_2|, and the redistribution against c_max = HyAB(green, blue)^0.7 =
// 41.2761 gives, for sRGB 0.5 against 0.6 (L* 53.389 and 63.264, computed independently in Python from the CIE
// formulas), 0.285013; 0.5 against 0.52 gives 0.093254. The channels are filtered in float (as FLIP's own
// implementation does): YCxCz values of ~60 carry ~1e-5 of rounding through the 21-tap filters, 5e-5 of the error.
TEST(Flip, AFlatDifferenceIsTheColourPipelinesClosedForm) {
    const Image grey = flat(32, 24, 0.5f, 0.5f, 0.5f);
    const std::vector<float> e1 = ldrFlip(grey, flat(32, 24, 0.6f, 0.6f, 0.6f));
    const std::vector<float> e2 = ldrFlip(grey, flat(32, 24, 0.52f, 0.52f, 0.52f));
    for (std::size_t i = 0; i < e1.size(); ++i) {
        ASSERT_NEAR(e1[i], 0.285013, 1e-4);
        ASSERT_NEAR(e2[i], 0.093254, 1e-4);
    }
    // The largest difference, green against blue, redistributes to 1.
    EXPECT_NEAR(ldrFlip(flat(32, 24, 0, 1, 0), flat(32, 24, 0, 0, 1))[300], 1.0, 1e-5);
}

// A vertical luminance step against the same step two pixels to the right: the error stands around the edges (the
// feature pipeline and the colour difference between them) and vanishes far from them.
TEST(Flip, AShiftedStepIsSeenAtTheEdgeOnly) {
    const int w = 96, h = 16;
    Image a = flat(w, h, 0.2f, 0.2f, 0.2f), b = a;
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x)
            for (int c = 0; c < 3; ++c) {
                a.at(x, y, c) = x >= 48 ? 0.8f : 0.2f;
                b.at(x, y, c) = x >= 50 ? 0.8f : 0.2f;
            }
    const std::vector<float> e = ldrFlip(a, b);
    const float atEdge = e[std::size_t(8) * w + 49],
                far = std::max(e[std::size_t(8) * w + 10], e[std::size_t(8) * w + 90]);
    std::printf("step: error at the edge %.3f, far from it %.2g\n", atEdge, far);
    EXPECT_GT(atEdge, 0.5f);
    EXPECT_LT(far, 1e-6f);
}

TEST(Flip, IsSymmetricInRangeAndGrowsWithTheDifference) {
    const Image base = noisy(48, 32, 2u, 0.3f);
    const Image small = noisy(48, 32, 3u, 0.02f, &base), large = noisy(48, 32, 4u, 0.2f, &base);
    const std::vector<float> ab = ldrFlip(base, large), ba = ldrFlip(large, base);
    for (std::size_t i = 0; i < ab.size(); ++i) {
        ASSERT_NEAR(ab[i], ba[i], 1e-6f);
        ASSERT_GE(ab[i], 0.0f);
        ASSERT_LE(ab[i], 1.0f);
    }
    const double meanSmall = flipStatistics(ldrFlip(base, small)).mean, meanLarge = flipStatistics(ab).mean;
    std::printf("mean FLIP: small noise %.4f, large noise %.4f\n", meanSmall, meanLarge);
    EXPECT_LT(meanSmall, 0.5 * meanLarge);
}

// On the calling thread alone (the studio's background pool) HDR-FLIP gives the same result as on TBB's threads.
TEST(Flip, OneThreadGivesTheSameResult) {
    const Image base = noisy(64, 40, 5u, 0.3f), test = noisy(64, 40, 6u, 0.1f, &base);
    HdrFlipSettings alone;
    alone.threads = 1;
    const HdrFlipResult everywhere = hdrFlip(base, test), serial = hdrFlip(base, test, alone);
    EXPECT_EQ(everywhere.error, serial.error);
    EXPECT_EQ(everywhere.exposureIndex, serial.exposureIndex);
    EXPECT_GT(flipStatistics(serial.error).mean, 0.0);
}

TEST(Flip, ToneMappersReachTheirKneeAtTheInverse) {
    for (const char* name : {"aces", "hable", "reinhard"}) {
        const FlipToneMapper t = flipToneMapperFromName(name);
        const double x = flipToneMapperInverse(t, 0.85);
        EXPECT_GT(x, 0.0) << name;
        EXPECT_NEAR(flipToneMap(t, x), 0.85, 1e-9) << name;
        EXPECT_LT(flipToneMap(t, 0.5 * x), 0.85) << name;
        EXPECT_EQ(flipToneMap(t, 0.0), 0.0) << name;
        EXPECT_EQ(flipToneMap(t, 1e30), 1.0) << name;
    }
    EXPECT_NEAR(flipToneMapperInverse(FlipToneMapper::Reinhard, 0.85), 0.85 / 0.15, 1e-12);
    EXPECT_THROW(flipToneMapperFromName("filmic"), InputError);
}

// A grey image of luminance 0.5 with one pixel of 8: start = log2(x_0.85 / 8), stop = log2(x_0.85 / 0.5), four
// exposures (ceil of the 4 stops between them).
TEST(Flip, TheExposureRangeFollowsTheReferencesMaximumAndMedian) {
    Image image = flat(9, 9, 0.5f, 0.5f, 0.5f);
    image.at(4, 4, 0) = image.at(4, 4, 1) = image.at(4, 4, 2) = 8.0f;
    double start = 0.0, stop = 0.0;
    flipExposureRange(image, FlipToneMapper::Aces, start, stop);
    const double knee = flipToneMapperInverse(FlipToneMapper::Aces, 0.85);
    EXPECT_NEAR(start, std::log2(knee / 8.0), 1e-6);
    EXPECT_NEAR(stop, std::log2(knee / 0.5), 1e-6);
    Image test = image;
    test.at(2, 2, 1) = 0.7f;
    const HdrFlipResult r = hdrFlip(image, test);
    EXPECT_EQ(r.exposures, 4);
    EXPECT_GT(r.error[std::size_t(2) * 9 + 2], 0.1f);
    EXPECT_THROW(ldrFlip(image, flat(8, 9, 0, 0, 0)), InputError);
}

TEST(Flip, WeightedStatistics) {
    // Errors 0.1, 0.2, 0.3, 0.4: total 1.0; a quarter of it is reached at 0.2 (0.3 cumulated), half at 0.3 (0.6), three
    // quarters at 0.4.
    const FlipStatistics s = flipStatistics({0.3f, 0.1f, 0.4f, 0.2f});
    EXPECT_NEAR(s.mean, 0.25, 1e-7);
    EXPECT_FLOAT_EQ(float(s.weightedFirstQuartile), 0.2f);
    EXPECT_FLOAT_EQ(float(s.weightedMedian), 0.3f);
    EXPECT_FLOAT_EQ(float(s.weightedThirdQuartile), 0.4f);
    EXPECT_FLOAT_EQ(float(s.minimum), 0.1f);
    EXPECT_FLOAT_EQ(float(s.maximum), 0.4f);
}

TEST(Flip, WeightedHistogram) {
    // 0.05 and 0.15 twice and 1.0 (in the last, closed bin) over 10 bins: counts 1, 2, ..., 1; shares by error.
    const std::vector<FlipHistogramBin> h = flipHistogram({0.05f, 0.15f, 0.15f, 1.0f}, 10);
    ASSERT_EQ(h.size(), 10u);
    EXPECT_EQ(h[0].pixels, 1);
    EXPECT_EQ(h[1].pixels, 2);
    EXPECT_EQ(h[9].pixels, 1);
    EXPECT_NEAR(h[0].weightedShare, 0.05 / 1.35, 1e-7);
    EXPECT_NEAR(h[1].weightedShare, 0.30 / 1.35, 1e-7);
    EXPECT_NEAR(h[9].weightedShare, 1.0 / 1.35, 1e-7);
    EXPECT_DOUBLE_EQ(h[9].high, 1.0);
}

}  // namespace
}  // namespace tyndall
