#include "tyndall/image/merge.h"

#include "tyndall/core/error.h"

#include <cmath>
#include <set>

namespace tyndall {

namespace {

const std::string& metadataOf(const Image& image, const std::string& path, const std::string& key) {
    const auto it = image.metadata.find(key);
    if (it == image.metadata.end())
        throw InputError(InputLocation{path, 0, 0, "metadata." + key},
                         "has no " + key + ": not a Tyndall render (merge takes the EXRs that tyndall render writes)");
    return it->second;
}

long long positiveCount(const Image& image, const std::string& path) {
    const std::string& text = metadataOf(image, path, "spp");
    long long spp = 0;
    try {
        spp = std::stoll(text);
    } catch (const std::exception&) {
        spp = 0;
    }
    if (spp < 1)
        throw InputError(InputLocation{path, 0, 0, "metadata.spp"},
                         "must be a positive sample count, got '" + text + "'");
    return spp;
}

}  // namespace

Image mergeRenders(const std::vector<Image>& images, const std::vector<std::string>& paths) {
    TY_CHECK(images.size() == paths.size(), "mergeRenders: one path per image");
    if (images.empty()) throw InputError(InputLocation{"", 0, 0, "images"}, "nothing to merge");
    const Image& first = images.front();
    // What makes two renders estimates of one image. ("reference" is absent from a view's render.)
    const char* identity[] = {"technique", "view", "reference", "projectHash", "parameters"};
    std::vector<long long> spp;
    std::set<std::string> seeds;
    long long total = 0;
    double seconds = 0.0;
    std::string seedList, shardList, fromList;
    for (std::size_t i = 0; i < images.size(); ++i) {
        const Image& image = images[i];
        const std::string& path = paths[i];
        if (image.width() != first.width() || image.height() != first.height())
            throw InputError(InputLocation{path, 0, 0, "size"}, "is " + std::to_string(image.width()) + " x " +
                                                                    std::to_string(image.height()) + ", but " +
                                                                    paths[0] + " is " + std::to_string(first.width()) +
                                                                    " x " + std::to_string(first.height()));
        if (image.channels() != first.channels())
            throw InputError(InputLocation{path, 0, 0, "channels"}, "has other channels than " + paths[0]);
        metadataOf(image, path, "projectHash");
        for (const char* key : identity) {
            const auto a = image.metadata.find(key), b = first.metadata.find(key);
            const bool same = (a == image.metadata.end()) == (b == first.metadata.end()) &&
                              (a == image.metadata.end() || a->second == b->second);
            if (!same)
                throw InputError(InputLocation{path, 0, 0, std::string("metadata.") + key},
                                 std::string("differs from ") + paths[0] + "'s: not a render of the same image (" +
                                     key + ": '" + (a == image.metadata.end() ? "" : a->second) + "' against '" +
                                     (b == first.metadata.end() ? "" : b->second) + "')");
        }
        const std::string& seed = metadataOf(image, path, "seed");
        if (!seeds.insert(seed).second)
            throw InputError(InputLocation{path, 0, 0, "metadata.seed"},
                             "has the seed " + seed +
                                 " of another input: its samples are not independent of it (render "
                                 "each shard with --shard I/N, which derives its seed)");
        spp.push_back(positiveCount(image, path));
        total += spp.back();
        if (const auto it = image.metadata.find("renderTime"); it != image.metadata.end()) {
            try {
                seconds += std::stod(it->second);
            } catch (const std::exception&) {
            }
        }
        const auto shard = image.metadata.find("shard");
        seedList += (i ? "," : "") + seed;
        shardList += (i ? "," : "") + (shard == image.metadata.end() ? std::string("-") : shard->second);
        fromList += (i ? "," : "") + path;
    }

    const int channels = first.channelCount();
    // For each channel, the index of its variance channel (-1: none), and whether it is one.
    std::vector<int> varianceOf(std::size_t(channels), -1);
    std::vector<bool> isVariance(std::size_t(channels), false);
    for (int c = 0; c < channels; ++c) {
        const std::string& name = first.channels()[std::size_t(c)];
        if (name.rfind("variance.", 0) == 0) {
            isVariance[std::size_t(c)] = true;
            continue;
        }
        varianceOf[std::size_t(c)] = first.channelIndex("variance." + name);
    }
    const double n = double(total);
    const double k = double(images.size());
    Image merged(first.width(), first.height(), first.channels());
    for (int y = 0; y < first.height(); ++y)
        for (int x = 0; x < first.width(); ++x)
            for (int c = 0; c < channels; ++c) {
                if (isVariance[std::size_t(c)]) continue;  // set with its channel (or below, if it has none)
                double mean = 0.0;
                for (std::size_t i = 0; i < images.size(); ++i)
                    mean += double(spp[i]) * double(images[i].at(x, y, c));
                mean /= n;
                merged.at(x, y, c) = float(mean);
                const int v = varianceOf[std::size_t(c)];
                if (v < 0) continue;
                double pooled = 0.0;
                for (std::size_t i = 0; i < images.size(); ++i) {
                    const double d = double(images[i].at(x, y, c)) - mean;
                    pooled += double(spp[i]) * (d * d + double(images[i].at(x, y, v)));
                }
                merged.at(x, y, v) = float(pooled / (n * (2.0 * k - 1.0)));
            }
    // A variance channel without its mean channel: the variance of a weighted mean of independent shards.
    for (int c = 0; c < channels; ++c) {
        if (!isVariance[std::size_t(c)]) continue;
        const std::string& name = first.channels()[std::size_t(c)];
        if (first.channelIndex(name.substr(9)) >= 0) continue;
        for (int y = 0; y < first.height(); ++y)
            for (int x = 0; x < first.width(); ++x) {
                double sum = 0.0;
                for (std::size_t i = 0; i < images.size(); ++i)
                    sum += double(spp[i]) * double(spp[i]) * double(images[i].at(x, y, c));
                merged.at(x, y, c) = float(sum / (n * n));
            }
    }
    merged.metadata = first.metadata;
    merged.metadata["spp"] = std::to_string(total);
    merged.metadata["renderTime"] = std::to_string(seconds);
    merged.metadata["seed"] = seedList;
    merged.metadata["shards"] = shardList;
    merged.metadata["mergedFrom"] = fromList;
    merged.metadata.erase("shard");
    return merged;
}

}  // namespace tyndall
