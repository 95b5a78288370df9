#include "tyndall/image/image_io.h"

#include "tyndall/core/error.h"
#include "tyndall/core/output.h"

#include <OpenImageIO/filesystem.h>
#include <OpenImageIO/imageio.h>

#include <algorithm>
#include <atomic>
#include <cctype>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <memory>
#include <random>
#include <set>
#include <sstream>
#include <system_error>
#include <vector>

namespace tyndall {

namespace fs = std::filesystem;

namespace {

// Metadata keys are stored in EXR headers as "tyndall:KEY", so that a key such as "compression" cannot collide with a
// standard attribute, and so that reading keeps our entries apart from what OIIO and other tools add.
constexpr std::string_view kMetadataPrefix = "tyndall:";
// OIIO's EXR writer drops empty string attributes, so an empty value is recorded as "tyndallEmpty:KEY" instead.
constexpr std::string_view kEmptyMetadataPrefix = "tyndallEmpty:";

// OpenEXR stores channels sorted by name and OIIO reorders them on reading; this attribute restores our order.
constexpr const char* kChannelOrderAttribute = "tyndallChannelOrder";

enum class Format { Exr, Png };

// What readImage accepts: an image header decides how much memory is allocated, so it is bounded: 2^28 values
// (pixels x channels, 1 GiB of floats; a 8192 x 8192 render with variance channels needs 2^26 x 6) and 64 channels.
constexpr std::int64_t kMaxReadValues = std::int64_t(1) << 28;
constexpr int kMaxReadChannels = 64;

std::string lowercase(std::string s) {
    std::transform(s.begin(), s.end(), s.begin(), [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
    return s;
}

InputError writeError(const std::string& path, const std::string& reason) {
    return InputError(InputLocation{.file = path}, "cannot write image: " + reason);
}

InputError readError(const std::string& path, const std::string& reason) {
    return InputError(InputLocation{.file = path}, "cannot read image: " + reason);
}

// OIIO keeps a per-thread error message besides the one on each ImageInput/ImageOutput; take whichever is set.
std::string oiioError(const std::string& local) {
    std::string global = OIIO::geterror();
    std::string message = !local.empty() ? local : global;
    return message.empty() ? std::string("unknown OpenImageIO error") : message;
}

Format formatOf(const std::string& path) {
    const std::string ext = lowercase(fs::path(path).extension().string());
    if (ext == ".exr") return Format::Exr;
    if (ext == ".png") return Format::Png;
    throw InputError(InputLocation{.file = path}, "unsupported image extension \"" +
                                                      fs::path(path).extension().string() + "\"; allowed: .exr, .png");
}

OIIO::ImageSpec exrSpec(const Image& image) {
    OIIO::ImageSpec spec(image.width(), image.height(), image.channelCount(), OIIO::TypeDesc::FLOAT);
    spec.channelnames = image.channels();
    spec.alpha_channel = -1;  // an "A" channel, if any, is data like any other: no premultiplication assumptions
    spec.attribute("compression", "zip");
    std::string order;
    for (const std::string& name : image.channels())
        order += (order.empty() ? "" : ",") + name;
    spec.attribute(kChannelOrderAttribute, order);
    for (const auto& [key, value] : image.metadata) {
        if (value.empty()) {
            spec.attribute(std::string(kEmptyMetadataPrefix) + key, "1");
        } else {
            spec.attribute(std::string(kMetadataPrefix) + key, value);
        }
    }
    return spec;
}

std::vector<std::uint8_t> pngPixels(const Image& image, double exposure, Tonemap op, const std::string& path) {
    Image rgb;
    try {
        rgb = image.select({"R", "G", "B"});
    } catch (const InputError& e) {
        throw writeError(path, "a PNG needs channels R, G, B (" + e.message() + ")");
    }
    std::vector<std::uint8_t> bytes(rgb.size());
    for (std::size_t i = 0; i + 2 < bytes.size(); i += 3) {
        const float* p = rgb.data() + i;
        const std::array<float, 3> d = tonemapRgb(p[0], p[1], p[2], exposure, op);
        for (int c = 0; c < 3; ++c) bytes[i + std::size_t(c)] = static_cast<std::uint8_t>(std::lround(d[std::size_t(c)] * 255.0f));
    }
    return bytes;
}

// For each channel in the order it was written (when the file records it), its index among the channels read back.
// Empty when the file does not record the order or the record does not match.
std::vector<int> channelPermutation(const std::vector<std::string>& read, const std::string& writtenOrder) {
    std::vector<std::string> written;
    std::stringstream list(writtenOrder);
    for (std::string name; std::getline(list, name, ',');)
        written.push_back(name);
    if (written.size() != read.size()) return {};
    std::vector<int> permutation;
    for (const std::string& name : written) {
        const auto it = std::find(read.begin(), read.end(), name);
        if (it == read.end()) return {};
        permutation.push_back(static_cast<int>(it - read.begin()));
    }
    return permutation;
}

}  // namespace

std::string encodeImage(const Image& image, const std::string& path, double exposure, Tonemap op) {
    const Format format = formatOf(path);
    if (image.empty() || image.channelCount() == 0) throw writeError(path, "the image is empty");

    OIIO::ImageSpec spec;
    std::vector<std::uint8_t> bytes;
    if (format == Format::Exr) {
        spec = exrSpec(image);
    } else {
        bytes = pngPixels(image, exposure, op, path);
        spec = OIIO::ImageSpec(image.width(), image.height(), 3, OIIO::TypeDesc::UINT8);
        spec.attribute("oiio:ColorSpace", "sRGB");
    }

    // Encoded in memory (OIIO's IOProxy), so that the file itself is written by writeFileAtomically with every step
    // checked and synced.
    std::vector<unsigned char> encoded;
    OIIO::Filesystem::IOVecOutput proxy(encoded);
    std::unique_ptr<OIIO::ImageOutput> out = OIIO::ImageOutput::create(path);
    if (!out) throw OutputError("cannot encode '" + path + "': " + oiioError(""));
    if (!out->supports("ioproxy") || !out->set_ioproxy(&proxy)) {
        throw OutputError("cannot encode '" + path + "': OpenImageIO's writer cannot write to memory");
    }
    if (!out->open(path, spec)) throw OutputError("cannot encode '" + path + "': " + oiioError(out->geterror()));
    const bool written = format == Format::Exr ? out->write_image(OIIO::TypeDesc::FLOAT, image.data())
                                               : out->write_image(OIIO::TypeDesc::UINT8, bytes.data());
    const std::string reason = written ? std::string() : oiioError(out->geterror());
    if (!out->close() && written) throw OutputError("cannot encode '" + path + "': " + oiioError(out->geterror()));
    if (!written) throw OutputError("cannot encode '" + path + "': " + reason);
    return std::string(encoded.begin(), encoded.end());
}

void writeImage(const Image& image, const std::string& path, double exposure, Tonemap op) {
    const fs::path directory = fs::path(path).parent_path().empty() ? fs::path(".") : fs::path(path).parent_path();
    std::error_code ec;
    if (!fs::is_directory(directory, ec)) {
        throw writeError(path, "directory \"" + directory.string() + "\" does not exist");
    }
    writeFileAtomically(path, encodeImage(image, path, exposure, op));
}

namespace {

// readImage; with `openExrAs` (the field that named the file) the file must hold an OpenEXR image, whatever its name.
Image readImageFile(const std::string& path, const std::string* openExrAs) {
    std::error_code ec;
    if (!fs::exists(path, ec)) throw readError(path, "no such file");
    if (!fs::is_regular_file(path, ec)) throw readError(path, "not a regular file");

    std::unique_ptr<OIIO::ImageInput> in = OIIO::ImageInput::open(path);
    if (!in) throw readError(path, oiioError(""));
    if (openExrAs && std::string(in->format_name()) != "openexr") {
        // By its content too: a PNG renamed .exr is still display values.
        throw InputError(InputLocation{.file = path, .field = *openExrAs},
                         "is named .exr but holds a " + std::string(in->format_name()) +
                             " image; metrics need an OpenEXR image of linear values");
    }
    const OIIO::ImageSpec& spec = in->spec();
    if (spec.deep) throw readError(path, "deep images are not supported");
    if (spec.depth > 1) throw readError(path, "volume images are not supported");
    if (spec.width <= 0 || spec.height <= 0 || spec.nchannels <= 0) throw readError(path, "the image is empty");
    if (spec.nchannels > kMaxReadChannels ||
        static_cast<std::int64_t>(spec.width) * spec.height * spec.nchannels > kMaxReadValues) {
        throw readError(path, std::to_string(spec.width) + " x " + std::to_string(spec.height) + " pixels of " +
                                  std::to_string(spec.nchannels) + " channels; at most " +
                                  std::to_string(kMaxReadValues) + " values (pixels x channels) and " +
                                  std::to_string(kMaxReadChannels) + " channels are read");
    }

    std::vector<std::string> names = spec.channelnames;
    names.resize(spec.nchannels);
    std::set<std::string> seen;
    for (std::size_t c = 0; c < names.size(); ++c) {
        if (names[c].empty()) names[c] = "channel" + std::to_string(c);
        if (!seen.insert(names[c]).second) throw readError(path, "duplicate channel \"" + names[c] + "\"");
    }

    // The data window of the first subimage, at full resolution. Every channel is converted to float.
    Image image(spec.width, spec.height, names);
    if (!in->read_image(0, 0, 0, spec.nchannels, OIIO::TypeDesc::FLOAT, image.data())) {
        throw readError(path, oiioError(in->geterror()));
    }

    const std::vector<int> permutation = channelPermutation(names, spec.get_string_attribute(kChannelOrderAttribute));
    if (!permutation.empty() && !std::is_sorted(permutation.begin(), permutation.end())) {
        std::vector<std::string> ordered;
        for (int c : permutation)
            ordered.push_back(names[c]);
        image = image.select(ordered);
    }

    for (const OIIO::ParamValue& attribute : spec.extra_attribs) {
        const std::string name = attribute.name().string();
        if (attribute.type() != OIIO::TypeDesc::STRING) continue;
        if (name.starts_with(kMetadataPrefix)) {
            image.metadata[name.substr(kMetadataPrefix.size())] = attribute.get_string();
        } else if (name.starts_with(kEmptyMetadataPrefix)) {
            image.metadata[name.substr(kEmptyMetadataPrefix.size())] = "";
        }
    }
    in->close();
    return image;
}

}  // namespace

Image readImage(const std::string& path) {
    return readImageFile(path, nullptr);
}

Image readLinearExr(const std::string& path, const std::string& field) {
    const std::string ext = lowercase(fs::path(path).extension().string());
    if (ext != ".exr") {
        const bool display = ext == ".png" || ext == ".jpg" || ext == ".jpeg" || ext == ".tif" || ext == ".tiff";
        throw InputError(InputLocation{.file = path, .field = field},
                         "must be an OpenEXR image (.exr), got " +
                             (ext.empty() ? std::string("a name without an extension") : "'" + ext + "'") +
                             (display ? ": metrics need linear values, and such a file holds display (tonemapped) ones"
                                      : ": metrics read the linear RGB and variance channels Tyndall writes to .exr "
                                        "(oiiotool converts other formats)"));
    }
    Image image = readImageFile(path, &field);
    long long nonFinite = 0;
    int firstX = -1, firstY = -1, firstChannel = -1;
    for (int y = 0; y < image.height(); ++y)
        for (int x = 0; x < image.width(); ++x)
            for (int c = 0; c < image.channelCount(); ++c)
                if (!std::isfinite(image.at(x, y, c)) && nonFinite++ == 0) firstX = x, firstY = y, firstChannel = c;
    if (nonFinite > 0) {
        throw InputError(InputLocation{.file = path, .field = field},
                         std::to_string(nonFinite) + " values are not finite (the first: pixel (" +
                             std::to_string(firstX) + ", " + std::to_string(firstY) + "), channel " +
                             image.channels()[std::size_t(firstChannel)] + ", " +
                             std::to_string(image.at(firstX, firstY, firstChannel)) +
                             "); metrics need finite values (Tyndall's renders count non-finite samples as 0)");
    }
    return image;
}

// Both evaluated in double, so that 1 maps to exactly 1 (in float, 1.055f - 0.055f is not 1).
float srgbEncode(float linear) {
    if (std::isnan(linear)) return 0.0f;
    const double x = linear;
    return static_cast<float>(x <= 0.0031308 ? 12.92 * x : 1.055 * std::pow(x, 1.0 / 2.4) - 0.055);
}

float srgbDecode(float encoded) {
    if (std::isnan(encoded)) return 0.0f;
    const double v = encoded;
    return static_cast<float>(v <= 0.04045 ? v / 12.92 : std::pow((v + 0.055) / 1.055, 2.4));
}

float tonemap(float linear, double exposure) {
    const float exposed = static_cast<float>(static_cast<double>(linear) * std::exp2(exposure));
    return std::clamp(srgbEncode(exposed), 0.0f, 1.0f);
}

}  // namespace tyndall
