// mergeRenders against synthetic shards whose statistics are known: each shard's pixel is the mean of two independent
// streams of n / 2 samples (as the reference renders them), its variance channel (a - b)^2 / 4.
#include "tyndall/image/merge.h"

#include "tyndall/core/error.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

namespace tyndall {
namespace {

// K shards of `spp[i]` samples of a pixel whose samples have mean mu(x, y) and variance sigma2.
std::vector<Image> syntheticShards(const std::vector<int>& spp, int size, double sigma2, std::uint32_t seed) {
    std::mt19937 rng(seed);
    std::vector<Image> shards;
    for (std::size_t i = 0; i < spp.size(); ++i) {
        Image image(size, size, {"R", "variance.R"});
        const double streamSd = std::sqrt(sigma2 / (0.5 * spp[i]));
        std::normal_distribution<double> noise(0.0, streamSd);
        for (int y = 0; y < size; ++y)
            for (int x = 0; x < size; ++x) {
                const double mu = 1.0 + 0.01 * x + 0.02 * y;
                const double a = mu + noise(rng), b = mu + noise(rng);
                image.at(x, y, 0) = float(0.5 * (a + b));
                image.at(x, y, 1) = float(0.25 * (a - b) * (a - b));
            }
        image.metadata = {{"technique", "reference"},
                          {"projectHash", "abc"},
                          {"parameters", "{}"},
                          {"spp", std::to_string(spp[i])},
                          {"seed", std::to_string(100 + i)},
                          {"renderTime", "1.5"},
                          {"shard", std::to_string(i) + "/" + std::to_string(spp.size())}};
        shards.push_back(std::move(image));
    }
    return shards;
}

std::vector<std::string> names(std::size_t n) {
    std::vector<std::string> out;
    for (std::size_t i = 0; i < n; ++i)
        out.push_back("shard" + std::to_string(i) + ".exr");
    return out;
}

// Four shards of 8 spp: the merged mean is the mean of the four, and the pooled variance (7 degrees of freedom per
// pixel) estimates the merged mean's variance, sigma2 / 32, without bias: its mean over 4096 pixels within 3 % (the
// spread of that mean is about 0.8 %), and the merged values' squared errors over it average 1 within 5 %.
TEST(MergeRenders, PoolsTheVarianceOfEqualShardsWithoutBias) {
    const double sigma2 = 0.3;
    const std::vector<Image> shards = syntheticShards({8, 8, 8, 8}, 64, sigma2, 7u);
    const Image merged = mergeRenders(shards, names(4));
    const double truth = sigma2 / 32.0;
    double meanVariance = 0.0, meanZ2 = 0.0, worstMean = 0.0;
    for (int y = 0; y < 64; ++y)
        for (int x = 0; x < 64; ++x) {
            double expected = 0.0;
            for (const Image& s : shards)
                expected += 0.25 * s.at(x, y, 0);
            worstMean = std::max(worstMean, std::abs(double(merged.at(x, y, 0)) - expected));
            const double mu = 1.0 + 0.01 * x + 0.02 * y;
            meanVariance += merged.at(x, y, 1) / truth;
            meanZ2 += (merged.at(x, y, 0) - mu) * (merged.at(x, y, 0) - mu) / truth;
        }
    meanVariance /= 4096.0;
    meanZ2 /= 4096.0;
    std::printf("pooled variance / truth %.4f, squared error / truth %.4f, mean within %.2g\n", meanVariance, meanZ2,
                worstMean);
    EXPECT_LT(worstMean, 1e-6);
    EXPECT_NEAR(meanVariance, 1.0, 0.03);
    EXPECT_NEAR(meanZ2, 1.0, 0.05);
    EXPECT_EQ(merged.metadata.at("spp"), "32");
    EXPECT_EQ(merged.metadata.at("seed"), "100,101,102,103");
    EXPECT_EQ(merged.metadata.at("shards"), "0/4,1/4,2/4,3/4");
    EXPECT_DOUBLE_EQ(std::stod(merged.metadata.at("renderTime")), 6.0);
    EXPECT_EQ(merged.metadata.count("shard"), 0u);
}

// Unequal shares (6 and 2 spp): the spp-weighted mean, and the
// pooled variance still unbiased when the per-sample variance is common.
TEST(MergeRenders, WeighsShardsByTheirSamples) {
    const double sigma2 = 0.5;
    const std::vector<Image> shards = syntheticShards({6, 2}, 64, sigma2, 11u);
    const Image merged = mergeRenders(shards, names(2));
    double meanVariance = 0.0, worstMean = 0.0;
    for (int y = 0; y < 64; ++y)
        for (int x = 0; x < 64; ++x) {
            const double expected = (6.0 * shards[0].at(x, y, 0) + 2.0 * shards[1].at(x, y, 0)) / 8.0;
            worstMean = std::max(worstMean, std::abs(double(merged.at(x, y, 0)) - expected));
            meanVariance += merged.at(x, y, 1) / (sigma2 / 8.0);
        }
    meanVariance /= 4096.0;
    std::printf("unequal shards: pooled variance / truth %.4f\n", meanVariance);
    EXPECT_LT(worstMean, 1e-6);
    EXPECT_NEAR(meanVariance, 1.0, 0.04);
    // One shard is itself.
    const Image one = mergeRenders({shards[0]}, names(1));
    EXPECT_EQ(one.at(5, 7, 0), shards[0].at(5, 7, 0));
    EXPECT_FLOAT_EQ(one.at(5, 7, 1), shards[0].at(5, 7, 1));
}

// What is not a shard of the same image is refused, naming the file and the field.
TEST(MergeRenders, RefusesRendersOfAnotherImageOrWithTheSameSeed) {
    const std::vector<Image> shards = syntheticShards({4, 4}, 8, 0.1, 3u);
    auto refusal = [&](std::vector<Image> images) -> std::string {
        try {
            mergeRenders(images, names(images.size()));
        } catch (const InputError& e) {
            return std::string(e.what());
        }
        return "";
    };
    std::vector<Image> sameSeed = shards;
    sameSeed[1].metadata["seed"] = sameSeed[0].metadata["seed"];
    EXPECT_NE(refusal(sameSeed).find("shard1.exr"), std::string::npos);
    EXPECT_NE(refusal(sameSeed).find("not independent"), std::string::npos);
    std::vector<Image> otherProject = shards;
    otherProject[1].metadata["projectHash"] = "def";
    EXPECT_NE(refusal(otherProject).find("metadata.projectHash"), std::string::npos);
    std::vector<Image> otherSize = shards;
    otherSize[1] = Image(9, 8, {"R", "variance.R"});
    otherSize[1].metadata = shards[1].metadata;
    EXPECT_NE(refusal(otherSize).find("9 x 8"), std::string::npos);
    std::vector<Image> noSpp = shards;
    noSpp[0].metadata.erase("spp");
    EXPECT_NE(refusal(noSpp).find("shard0.exr"), std::string::npos);
    std::vector<Image> view = shards;
    view[1].metadata["view"] = "fog";  // a view's render beside the reference
    EXPECT_NE(refusal(view).find("metadata.view"), std::string::npos);
}

}  // namespace
}  // namespace tyndall
