// A float image with named channels and string metadata (model: tev keeps Image apart from its viewer). Renderers
// hand results out as Images; the CLI writes them with image_io.h and the studio uploads them for display.
#pragma once

#include <cstddef>
#include <map>
#include <string>
#include <vector>

namespace tyndall {

class Image {
public:
    Image() = default;
    // Channels named as in EXR: "R", "G", "B", then extras such as "variance.R" or "ratio.num".
    Image(int width, int height, std::vector<std::string> channels);
    static Image rgb(int width, int height) { return Image(width, height, {"R", "G", "B"}); }

    int width() const { return width_; }
    int height() const { return height_; }
    int channelCount() const { return static_cast<int>(channels_.size()); }
    const std::vector<std::string>& channels() const { return channels_; }
    int channelIndex(const std::string& name) const;  // -1 when absent
    bool empty() const { return width_ == 0 || height_ == 0; }

    // Pixels are stored row-major from the top-left, channels interleaved.
    float& at(int x, int y, int c) { return data_[index(x, y, c)]; }
    float at(int x, int y, int c) const { return data_[index(x, y, c)]; }
    float* data() { return data_.data(); }
    const float* data() const { return data_.data(); }
    std::size_t size() const { return data_.size(); }

    // A copy holding only the named channels, in that order; throws InputError when one is missing.
    Image select(const std::vector<std::string>& names) const;
    // Appends channels (initialised to zero) and returns the index of the first.
    int addChannels(const std::vector<std::string>& names);

    // String metadata written into EXR headers: technique, parameters, spp, renderTime, seed, projectHash, tyndallVersion.
    std::map<std::string, std::string> metadata;

private:
    std::size_t index(int x, int y, int c) const {
        return (static_cast<std::size_t>(y) * width_ + x) * channels_.size() + c;
    }
    int width_ = 0, height_ = 0;
    std::vector<std::string> channels_;
    std::vector<float> data_;
};

}  // namespace tyndall
