#include "tyndall/image/image_io.h"

#include "tyndall/core/error.h"
#include "tyndall/core/output.h"

#include <ImfChannelList.h>
#include <ImfFrameBuffer.h>
#include <ImfHeader.h>
#include <ImfIO.h>
#include <ImfInputFile.h>
#include <ImfOutputFile.h>
#include <ImfStringAttribute.h>
#include <ImfTestFile.h>
#include <ImfThreading.h>
#include <png.h>

#include <algorithm>
#include <array>
#include <cctype>
#include <cerrno>
#include <cmath>
#include <csetjmp>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <exception>
#include <filesystem>
#include <fstream>
#include <map>
#include <memory>
#include <mutex>
#include <set>
#include <sstream>
#include <system_error>
#include <thread>
#include <vector>

namespace tyndall {

namespace fs = std::filesystem;

namespace {

// Metadata keys are stored in EXR headers as "tyndall:KEY", so that a key such as "compression" cannot collide with a
// standard attribute, and so that reading keeps our entries apart from what other tools add.
constexpr std::string_view kMetadataPrefix = "tyndall:";
// Files written through OpenImageIO (before 0.1.0) recorded an empty value as "tyndallEmpty:KEY", as its EXR writer
// dropped empty strings; such files are still read.
constexpr std::string_view kEmptyMetadataPrefix = "tyndallEmpty:";

// OpenEXR stores channels sorted by name; this attribute restores our order.
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

Format formatOf(const std::string& path) {
    const std::string ext = lowercase(fs::path(path).extension().string());
    if (ext == ".exr") return Format::Exr;
    if (ext == ".png") return Format::Png;
    throw InputError(InputLocation{.file = path}, "unsupported image extension \"" +
                                                      fs::path(path).extension().string() + "\"; allowed: .exr, .png");
}

// OpenEXR compresses and decompresses blocks of scanlines on its global thread pool; set up once, on first use.
void useExrThreads() {
    static std::once_flag once;
    std::call_once(once, [] {
        Imf::setGlobalThreadCount(static_cast<int>(std::clamp(std::thread::hardware_concurrency(), 1u, 8u)));
    });
}

// An OpenEXR output stream into memory, so that the file itself is written by writeFileAtomically with every step
// checked and synced. OpenEXR seeks back to patch its line-offset table, hence the position.
class MemoryExrStream final : public Imf::OStream {
public:
    explicit MemoryExrStream(std::string& bytes) : Imf::OStream("memory"), bytes_(bytes) {}
    void write(const char c[], int n) override {
        const std::size_t end = position_ + static_cast<std::size_t>(n);
        if (end > bytes_.size()) bytes_.resize(end);
        std::memcpy(bytes_.data() + position_, c, static_cast<std::size_t>(n));
        position_ = end;
    }
    std::uint64_t tellp() override { return position_; }
    void seekp(std::uint64_t position) override { position_ = static_cast<std::size_t>(position); }

private:
    std::string& bytes_;
    std::size_t position_ = 0;
};

std::string encodeExr(const Image& image) {
    useExrThreads();
    Imf::Header header(image.width(), image.height());
    header.compression() = Imf::ZIP_COMPRESSION;
    std::string order;
    for (const std::string& name : image.channels()) {
        header.channels().insert(name, Imf::Channel(Imf::FLOAT));
        order += (order.empty() ? "" : ",") + name;
    }
    header.insert(kChannelOrderAttribute, Imf::StringAttribute(order));
    for (const auto& [key, value] : image.metadata)
        header.insert(std::string(kMetadataPrefix) + key, Imf::StringAttribute(value));

    const std::size_t pixelStride = sizeof(float) * static_cast<std::size_t>(image.channelCount());
    Imf::FrameBuffer frame;
    for (int c = 0; c < image.channelCount(); ++c) {
        // OpenEXR's slices take a mutable pointer for reading and writing alike; writing only reads through it.
        char* base = reinterpret_cast<char*>(const_cast<float*>(image.data() + c));
        frame.insert(image.channels()[std::size_t(c)],
                     Imf::Slice(Imf::FLOAT, base, pixelStride, pixelStride * static_cast<std::size_t>(image.width())));
    }
    std::string bytes;
    MemoryExrStream stream(bytes);
    Imf::OutputFile file(stream, header, Imf::globalThreadCount());
    file.setFrameBuffer(frame);
    file.writePixels(image.height());
    return bytes;
}

std::vector<std::uint8_t> pngPixels(const Image& image, double exposure, const DisplayTransform& display,
                                    const std::string& path) {
    Image rgb;
    try {
        rgb = image.select({"R", "G", "B"});
    } catch (const InputError& e) {
        throw writeError(path, "a PNG needs channels R, G, B (" + e.message() + ")");
    }
    display.apply(rgb.data(), std::size_t(rgb.width()) * std::size_t(rgb.height()), exposure);
    std::vector<std::uint8_t> bytes(rgb.size());
    for (std::size_t i = 0; i < bytes.size(); ++i)
        bytes[i] = static_cast<std::uint8_t>(std::lround(rgb.data()[i] * 255.0f));
    return bytes;
}

// libpng reports errors through a callback that must not return: it records the message (in the string given as the
// error pointer) and jumps back to the caller's setjmp. Warnings are ignored.
void pngError(png_structp png, png_const_charp message) {
    *static_cast<std::string*>(png_get_error_ptr(png)) = message;
    png_longjmp(png, 1);
}

void pngWarning(png_structp, png_const_charp) {}

struct PngWrite {
    png_structp png = nullptr;
    png_infop info = nullptr;
    std::string message;
    ~PngWrite() { png_destroy_write_struct(&png, &info); }
};

// The image's metadata and how its values were shown (the display transform and exposure), as PNG text chunks under
// the keys "tyndall:KEY" that readPng gives back as metadata; long values compressed (zTXt).
std::vector<std::pair<std::string, std::string>> pngText(const Image& image, double exposure,
                                                         const DisplayTransform& display) {
    std::map<std::string, std::string> entries(image.metadata.begin(), image.metadata.end());
    if (display.isOcio()) {
        entries["display"] = display.display();
        entries["view"] = display.view();
        entries["ocioConfig"] = display.config()->file().empty() ? "raw" : display.config()->file();
        entries.erase("tonemap");
    } else {
        entries["tonemap"] = display.name();
        for (const char* key : {"display", "view", "ocioConfig"})
            entries.erase(key);
    }
    entries["displayExposure"] = std::to_string(exposure);
    std::vector<std::pair<std::string, std::string>> out;
    for (const auto& [key, value] : entries) {
        const std::string name = std::string(kMetadataPrefix) + key;
        if (name.size() <= 79) out.emplace_back(name, value);  // PNG's limit on a keyword
    }
    return out;
}

// The libpng calls on their own, so that nothing but libpng's state lives across its setjmp.
void writePng(PngWrite& write, std::string& bytes, int width, int height, bool srgb, std::vector<png_text>& chunks,
              std::vector<png_bytep>& rows) {
    write.png = png_create_write_struct(PNG_LIBPNG_VER_STRING, &write.message, pngError, pngWarning);
    if (!write.png) throw std::bad_alloc();
    write.info = png_create_info_struct(write.png);
    if (!write.info) throw std::bad_alloc();
    if (setjmp(png_jmpbuf(write.png))) throw OutputError("cannot encode PNG: " + write.message);
    png_set_write_fn(
        write.png, &bytes,
        [](png_structp png, png_bytep data, png_size_t size) {
            static_cast<std::string*>(png_get_io_ptr(png))->append(reinterpret_cast<const char*>(data), size);
        },
        [](png_structp) {});
    png_set_IHDR(write.png, write.info, png_uint_32(width), png_uint_32(height), 8, PNG_COLOR_TYPE_RGB,
                 PNG_INTERLACE_NONE, PNG_COMPRESSION_TYPE_DEFAULT, PNG_FILTER_TYPE_DEFAULT);
    if (srgb) png_set_sRGB_gAMA_and_cHRM(write.png, write.info, PNG_sRGB_INTENT_PERCEPTUAL);
    png_set_text(write.png, write.info, chunks.data(), int(chunks.size()));
    png_set_rows(write.png, write.info, rows.data());
    png_write_png(write.png, write.info, PNG_TRANSFORM_IDENTITY, nullptr);
}

std::string encodePng(const Image& image, double exposure, const DisplayTransform& display, const std::string& path) {
    const std::vector<std::uint8_t> pixels = pngPixels(image, exposure, display, path);
    std::vector<std::pair<std::string, std::string>> text = pngText(image, exposure, display);
    std::vector<png_text> chunks(text.size());
    for (std::size_t i = 0; i < text.size(); ++i) {
        chunks[i].compression = text[i].second.size() > 1024 ? PNG_TEXT_COMPRESSION_zTXt : PNG_TEXT_COMPRESSION_NONE;
        chunks[i].key = text[i].first.data();
        chunks[i].text = text[i].second.data();
        chunks[i].text_length = text[i].second.size();
    }
    std::vector<png_bytep> rows(static_cast<std::size_t>(image.height()));
    for (std::size_t y = 0; y < rows.size(); ++y)
        rows[y] = const_cast<png_bytep>(pixels.data() + y * std::size_t(image.width()) * 3);
    // Tyndall's operators and an OpenColorIO sRGB display make sRGB values: said by an sRGB chunk, which other
    // displays (Rec.1886, P3) leave out rather than mislabel.
    std::string displayName = display.display();
    std::transform(displayName.begin(), displayName.end(), displayName.begin(),
                   [](unsigned char c) { return char(std::tolower(c)); });
    const bool srgb = !display.isOcio() || displayName.find("srgb") != std::string::npos;
    std::string bytes;
    PngWrite write;
    writePng(write, bytes, image.width(), image.height(), srgb, chunks, rows);
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

// The data window of the first part, at full resolution (level 0 of a tiled file), every channel converted to float.
Image readExr(const std::string& path) {
    useExrThreads();
    bool tiled = false, deep = false, multiPart = false;
    if (!Imf::isOpenExrFile(path.c_str(), tiled, deep, multiPart)) throw readError(path, "not an OpenEXR file");
    if (deep) throw readError(path, "deep images are not supported");
    Imf::InputFile file(path.c_str(), Imf::globalThreadCount());
    const Imf::Header& header = file.header();
    const Imath::Box2i window = header.dataWindow();
    const std::int64_t width = std::int64_t(window.max.x) - window.min.x + 1;
    const std::int64_t height = std::int64_t(window.max.y) - window.min.y + 1;
    std::vector<std::string> names;
    for (auto it = header.channels().begin(); it != header.channels().end(); ++it) {
        if (it.channel().xSampling != 1 || it.channel().ySampling != 1) {
            throw readError(path, "channel \"" + std::string(it.name()) + "\" is subsampled (" +
                                      std::to_string(it.channel().xSampling) + " x " +
                                      std::to_string(it.channel().ySampling) +
                                      "); only full-resolution channels are read");
        }
        names.emplace_back(it.name());
    }
    checkReadableImageSize(path, width, height, static_cast<std::int64_t>(names.size()));

    Image image(static_cast<int>(width), static_cast<int>(height), names);
    const std::size_t pixelStride = sizeof(float) * names.size();
    Imf::FrameBuffer frame;
    for (std::size_t c = 0; c < names.size(); ++c) {
        frame.insert(names[c], Imf::Slice::Make(Imf::FLOAT, image.data() + c, window, pixelStride,
                                                pixelStride * static_cast<std::size_t>(width)));
    }
    file.setFrameBuffer(frame);
    file.readPixels(window.min.y, window.max.y);

    std::string order;
    for (auto it = header.begin(); it != header.end(); ++it) {
        const auto* text = dynamic_cast<const Imf::StringAttribute*>(&it.attribute());
        if (!text) continue;
        const std::string name = it.name();
        if (name == kChannelOrderAttribute) {
            order = text->value();
        } else if (name.starts_with(kMetadataPrefix)) {
            image.metadata[name.substr(kMetadataPrefix.size())] = text->value();
        } else if (name.starts_with(kEmptyMetadataPrefix)) {
            image.metadata[name.substr(kEmptyMetadataPrefix.size())] = "";
        }
    }
    const std::vector<int> permutation = channelPermutation(names, order);
    if (!permutation.empty() && !std::is_sorted(permutation.begin(), permutation.end())) {
        std::vector<std::string> ordered;
        for (int c : permutation)
            ordered.push_back(names[std::size_t(c)]);
        image = image.select(ordered);  // keeps the metadata
    }
    return image;
}

// The read state, freed on every path (a jump back from pngError included).
struct PngRead {
    png_structp png = nullptr;
    png_infop info = nullptr;
    std::FILE* file = nullptr;
    std::string message;
    ~PngRead() {
        png_destroy_read_struct(&png, &info, nullptr);
        if (file) std::fclose(file);
    }
};

// Any PNG (grey, grey + alpha, RGB, RGBA, palette, 1 to 16 bits; transparency as alpha) as its stored values, v / 255
// or v / 65535: channels Y, Y A, R G B or R G B A. The display transfer function is the caller's to undo.
Image readPng(const std::string& path) {
    // Everything that lives across setjmp is declared before it, so that a jump back skips no destructor.
    PngRead read;
    std::vector<std::uint8_t> bytes;
    std::vector<png_bytep> rows;
    Image image;
    std::map<std::string, std::string> metadata;
    read.file = std::fopen(path.c_str(), "rb");
    if (!read.file) throw readError(path, std::strerror(errno));
    read.png = png_create_read_struct(PNG_LIBPNG_VER_STRING, &read.message, pngError, pngWarning);
    if (!read.png) throw std::bad_alloc();
    read.info = png_create_info_struct(read.png);
    if (!read.info) throw std::bad_alloc();
    if (setjmp(png_jmpbuf(read.png))) throw readError(path, "damaged PNG: " + read.message);
    png_init_io(read.png, read.file);
    png_read_info(read.png, read.info);
    png_set_expand(read.png);  // palette to RGB, < 8 bits to 8, tRNS to alpha
    if (png_get_bit_depth(read.png, read.info) == 16) png_set_swap(read.png);  // to this machine's byte order
    png_read_update_info(read.png, read.info);
    png_textp text = nullptr;
    const int texts = png_get_text(read.png, read.info, &text, nullptr);
    for (int i = 0; i < texts; ++i) {
        const std::string key = text[i].key;
        if (key.starts_with(kMetadataPrefix))
            metadata[key.substr(kMetadataPrefix.size())] = text[i].text;  // NUL-terminated (iTXt has no text_length)
    }
    const std::int64_t width = png_get_image_width(read.png, read.info);
    const std::int64_t height = png_get_image_height(read.png, read.info);
    const int channels = png_get_channels(read.png, read.info);
    const int depth = png_get_bit_depth(read.png, read.info);
    checkReadableImageSize(path, width, height, channels);
    const std::size_t rowBytes = png_get_rowbytes(read.png, read.info);
    bytes.resize(rowBytes * static_cast<std::size_t>(height));
    rows.resize(static_cast<std::size_t>(height));
    for (std::size_t y = 0; y < rows.size(); ++y)
        rows[y] = bytes.data() + y * rowBytes;
    png_read_image(read.png, rows.data());
    png_read_end(read.png, nullptr);

    static const std::vector<std::string> kNames[4] = {{"Y"}, {"Y", "A"}, {"R", "G", "B"}, {"R", "G", "B", "A"}};
    image = Image(static_cast<int>(width), static_cast<int>(height), kNames[channels - 1]);
    const std::size_t values = image.size();
    if (depth == 16) {
        for (std::size_t i = 0; i < values; ++i) {
            std::uint16_t v;
            std::memcpy(&v, bytes.data() + 2 * i, sizeof v);
            image.data()[i] = static_cast<float>(v) / 65535.0f;
        }
    } else {
        for (std::size_t i = 0; i < values; ++i)
            image.data()[i] = static_cast<float>(bytes[i]) / 255.0f;
    }
    image.metadata.insert(metadata.begin(), metadata.end());
    return image;
}

// The file's first bytes, as many as the longest magic number (fewer for a shorter file).
std::string fileHead(const std::string& path) {
    std::ifstream in(path, std::ios::binary);
    std::string head(8, '\0');
    in.read(head.data(), static_cast<std::streamsize>(head.size()));
    head.resize(static_cast<std::size_t>(std::max<std::streamsize>(in.gcount(), 0)));
    return head;
}

constexpr std::string_view kExrMagic("\x76\x2f\x31\x01", 4);
constexpr std::string_view kPngMagic("\x89PNG\r\n\x1a\n", 8);

}  // namespace

void checkReadableImageSize(const std::string& path, std::int64_t width, std::int64_t height, std::int64_t channels) {
    if (width <= 0 || height <= 0 || channels <= 0) throw readError(path, "the image is empty");
    if (channels > kMaxReadChannels || width > kMaxReadValues || height > kMaxReadValues ||
        width * height * channels > kMaxReadValues) {
        throw readError(path, std::to_string(width) + " x " + std::to_string(height) + " pixels of " +
                                  std::to_string(channels) + " channels; at most " + std::to_string(kMaxReadValues) +
                                  " values (pixels x channels) and " + std::to_string(kMaxReadChannels) +
                                  " channels are read");
    }
}

std::string encodeImage(const Image& image, const std::string& path, double exposure, const DisplayTransform& display) {
    const Format format = formatOf(path);
    if (image.empty() || image.channelCount() == 0) throw writeError(path, "the image is empty");
    try {
        return format == Format::Exr ? encodeExr(image) : encodePng(image, exposure, display, path);
    } catch (const InputError&) {
        throw;
    } catch (const OutputError&) {
        throw;
    } catch (const std::exception& e) {  // OpenEXR's exceptions (Iex::BaseExc), std::bad_alloc
        throw OutputError("cannot encode '" + path + "': " + e.what());
    }
}

void writeImage(const Image& image, const std::string& path, double exposure, const DisplayTransform& display) {
    const fs::path directory = fs::path(path).parent_path().empty() ? fs::path(".") : fs::path(path).parent_path();
    std::error_code ec;
    if (!fs::is_directory(directory, ec)) {
        throw writeError(path, "directory \"" + directory.string() + "\" does not exist");
    }
    writeFileAtomically(path, encodeImage(image, path, exposure, display));
}

namespace {

// readImage; with `openExrAs` (the field that named the file) the file must hold an OpenEXR image, whatever its name.
// The format is decided by the file's first bytes, not its name.
Image readImageFile(const std::string& path, const std::string* openExrAs) {
    std::error_code ec;
    if (!fs::exists(path, ec)) throw readError(path, "no such file");
    if (!fs::is_regular_file(path, ec)) throw readError(path, "not a regular file");

    const std::string head = fileHead(path);
    const bool exr = head.starts_with(kExrMagic), png = head.starts_with(kPngMagic);
    if (openExrAs && !exr) {
        // By its content too: a PNG renamed .exr is still display values.
        throw InputError(InputLocation{.file = path, .field = *openExrAs},
                         std::string("is named .exr but holds ") + (png ? "a png image" : "no OpenEXR image") +
                             "; metrics need an OpenEXR image of linear values");
    }
    if (!exr && !png) {
        throw readError(path,
                        "neither an OpenEXR nor a PNG file (the library reads those two; the studio also opens "
                        "HDR, PFM, JPEG, TIFF, BMP and TGA)");
    }
    try {
        return exr ? readExr(path) : readPng(path);
    } catch (const InputError&) {
        throw;
    } catch (const std::exception& e) {  // OpenEXR's exceptions for a damaged file (Iex::BaseExc), std::bad_alloc
        throw readError(path, e.what());
    }
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
