#include "tyndall/image/image.h"

#include "tyndall/core/error.h"

#include <algorithm>
#include <limits>
#include <set>
#include <utility>

namespace tyndall {

namespace {

// Channel names must be non-empty and distinct: EXR addresses channels by name, and so do select() and the metrics.
void checkChannelNames(const std::vector<std::string>& names) {
    std::set<std::string> seen;
    for (const std::string& name : names) {
        TY_CHECK(!name.empty(), "channel names must not be empty");
        TY_CHECK(seen.insert(name).second, "duplicate channel name \"" + name + "\"");
    }
}

std::string joinNames(const std::vector<std::string>& names) {
    std::string out;
    for (const std::string& name : names) {
        if (!out.empty()) out += ", ";
        out += name;
    }
    return out.empty() ? "none" : out;
}

}  // namespace

Image::Image(int width, int height, std::vector<std::string> channels)
    : width_(width), height_(height), channels_(std::move(channels)) {
    TY_CHECK(width >= 0 && height >= 0,
             "image size must be >= 0, got " + std::to_string(width) + "x" + std::to_string(height));
    checkChannelNames(channels_);
    const std::size_t pixels = static_cast<std::size_t>(width) * static_cast<std::size_t>(height);
    TY_CHECK(channels_.empty() || pixels <= std::numeric_limits<std::size_t>::max() / channels_.size(),
             "image too large");
    data_.assign(pixels * channels_.size(), 0.0f);
}

int Image::channelIndex(const std::string& name) const {
    const auto it = std::find(channels_.begin(), channels_.end(), name);
    return it == channels_.end() ? -1 : static_cast<int>(it - channels_.begin());
}

Image Image::select(const std::vector<std::string>& names) const {
    std::vector<int> source;
    source.reserve(names.size());
    for (const std::string& name : names) {
        const int c = channelIndex(name);
        if (c < 0) {
            throw InputError(InputLocation{.field = "channels"},
                             "no channel \"" + name + "\"; the image has " + joinNames(channels_));
        }
        source.push_back(c);
    }

    Image out(width_, height_, names);
    out.metadata = metadata;
    const std::size_t pixels = static_cast<std::size_t>(width_) * height_;
    const std::size_t inStride = channels_.size(), outStride = names.size();
    for (std::size_t p = 0; p < pixels; ++p) {
        for (std::size_t c = 0; c < outStride; ++c)
            out.data_[p * outStride + c] = data_[p * inStride + source[c]];
    }
    return out;
}

int Image::addChannels(const std::vector<std::string>& names) {
    std::vector<std::string> all = channels_;
    all.insert(all.end(), names.begin(), names.end());
    checkChannelNames(all);

    // Channels are interleaved, so every pixel moves: rebuild the buffer with the new channels zeroed.
    const int first = channelCount();
    const std::size_t pixels = static_cast<std::size_t>(width_) * height_;
    const std::size_t oldStride = channels_.size(), newStride = all.size();
    std::vector<float> data(pixels * newStride, 0.0f);
    for (std::size_t p = 0; p < pixels; ++p) {
        std::copy_n(data_.begin() + p * oldStride, oldStride, data.begin() + p * newStride);
    }
    channels_ = std::move(all);
    data_ = std::move(data);
    return first;
}

}  // namespace tyndall
