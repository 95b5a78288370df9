// Tests of Image (channels, select, addChannels) and of image_io (EXR and PNG writing, reading, sRGB).
#include "tyndall/core/error.h"
#include "tyndall/image/colour_map.h"
#include "tyndall/image/image.h"
#include "tyndall/image/image_io.h"
#include "tyndall/image/metrics.h"
#include "tyndall/image/tonemap.h"

#include <ImfChannelList.h>
#include <ImfFrameBuffer.h>
#include <ImfHeader.h>
#include <ImfOutputFile.h>
#include <ImfTiledOutputFile.h>
#include <gtest/gtest.h>
#include <png.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <string>
#include <vector>

namespace tyndall {
namespace {

namespace fs = std::filesystem;

// A fresh, empty directory for one test, so that tests can check what files a write leaves behind.
fs::path testDirectory(const std::string& name) {
    const fs::path dir = fs::path(TYNDALL_TEST_TMP) / "image" / name;
    fs::remove_all(dir);
    fs::create_directories(dir);
    return dir;
}

std::vector<std::string> filesIn(const fs::path& dir) {
    std::vector<std::string> names;
    for (const auto& entry : fs::directory_iterator(dir))
        names.push_back(entry.path().filename().string());
    std::sort(names.begin(), names.end());
    return names;
}

// The 8-bit value a PNG holds, from readImage's float (stored values v are read as v / 255).
int byteOf(float value) {
    return static_cast<int>(std::lround(value * 255.0f));
}

// ---------------------------------------------------------------------------------------------------------------------
// Image

TEST(Image, ConstructorZeroesPixelsAndRejectsBadSizes) {
    const Image image(3, 2, {"R", "G", "B", "variance.R"});
    EXPECT_EQ(image.width(), 3);
    EXPECT_EQ(image.height(), 2);
    EXPECT_EQ(image.channelCount(), 4);
    ASSERT_EQ(image.size(), 3u * 2u * 4u);
    for (std::size_t i = 0; i < image.size(); ++i)
        EXPECT_EQ(image.data()[i], 0.0f);

    EXPECT_TRUE(Image().empty());
    EXPECT_THROW(Image(-1, 2, {"R"}), ContractError);
    EXPECT_THROW(Image(2, -1, {"R"}), ContractError);
    EXPECT_THROW(Image(2, 2, {"R", "R"}), ContractError);
    EXPECT_THROW(Image(2, 2, {"R", ""}), ContractError);
}

TEST(Image, PixelsAreRowMajorWithInterleavedChannels) {
    Image image = Image::rgb(3, 2);
    image.at(2, 1, 1) = 7.0f;  // last row, last column, G
    EXPECT_EQ(image.data()[(1 * 3 + 2) * 3 + 1], 7.0f);
    EXPECT_EQ(image.channelIndex("R"), 0);
    EXPECT_EQ(image.channelIndex("B"), 2);
    EXPECT_EQ(image.channelIndex("A"), -1);
}

TEST(Image, SelectReordersChannelsAndKeepsMetadata) {
    Image image(2, 1, {"R", "G", "B", "variance.R"});
    image.metadata["spp"] = "64";
    for (int x = 0; x < 2; ++x) {
        for (int c = 0; c < 4; ++c)
            image.at(x, 0, c) = static_cast<float>(10 * x + c);
    }
    const Image selected = image.select({"variance.R", "R"});
    ASSERT_EQ(selected.channels(), (std::vector<std::string>{"variance.R", "R"}));
    EXPECT_EQ(selected.at(0, 0, 0), 3.0f);
    EXPECT_EQ(selected.at(0, 0, 1), 0.0f);
    EXPECT_EQ(selected.at(1, 0, 0), 13.0f);
    EXPECT_EQ(selected.at(1, 0, 1), 10.0f);
    EXPECT_EQ(selected.metadata.at("spp"), "64");
}

TEST(Image, SelectNamesTheMissingChannel) {
    const Image image = Image::rgb(2, 2);
    try {
        (void)image.select({"R", "variance.G"});
        FAIL() << "expected InputError";
    } catch (const InputError& e) {
        EXPECT_NE(std::string(e.what()).find("variance.G"), std::string::npos) << e.what();
    }
}

TEST(Image, AddChannelsKeepsPixelsAndZeroesNewChannels) {
    Image image = Image::rgb(2, 2);
    for (int y = 0; y < 2; ++y) {
        for (int x = 0; x < 2; ++x) {
            for (int c = 0; c < 3; ++c)
                image.at(x, y, c) = static_cast<float>(100 * y + 10 * x + c + 1);
        }
    }
    const int first = image.addChannels({"variance.R", "variance.G"});
    EXPECT_EQ(first, 3);
    ASSERT_EQ(image.channelCount(), 5);
    EXPECT_EQ(image.channels()[4], "variance.G");
    for (int y = 0; y < 2; ++y) {
        for (int x = 0; x < 2; ++x) {
            for (int c = 0; c < 3; ++c)
                EXPECT_EQ(image.at(x, y, c), static_cast<float>(100 * y + 10 * x + c + 1));
            EXPECT_EQ(image.at(x, y, 3), 0.0f);
            EXPECT_EQ(image.at(x, y, 4), 0.0f);
        }
    }
    EXPECT_THROW(image.addChannels({"R"}), ContractError);
}

// ---------------------------------------------------------------------------------------------------------------------
// sRGB

TEST(ImageTonemap, SrgbTransferFunction) {
    EXPECT_FLOAT_EQ(srgbEncode(0.0f), 0.0f);
    EXPECT_NEAR(srgbEncode(1.0f), 1.0f, 1e-6f);
    EXPECT_FLOAT_EQ(srgbEncode(0.002f), 12.92f * 0.002f);  // the linear segment, below 0.0031308
    EXPECT_NEAR(srgbEncode(0.5f), 0.735357f, 1e-5f);       // 1.055 * 0.5^(1/2.4) - 0.055
    for (float v : {0.0f, 0.001f, 0.01f, 0.2f, 0.5f, 0.9f, 1.0f})
        EXPECT_NEAR(srgbDecode(srgbEncode(v)), v, 1e-6f);
}

TEST(ImageTonemap, AppliesExposureClampsAndZeroesNan) {
    EXPECT_NEAR(tonemap(0.25f, 1.0), srgbEncode(0.5f), 1e-7f);
    EXPECT_NEAR(tonemap(1.0f, -1.0), srgbEncode(0.5f), 1e-7f);
    EXPECT_EQ(tonemap(4.0f, 0.0), 1.0f);
    EXPECT_EQ(tonemap(std::numeric_limits<float>::infinity(), 0.0), 1.0f);
    EXPECT_EQ(tonemap(-0.5f, 0.0), 0.0f);
    EXPECT_EQ(tonemap(std::numeric_limits<float>::quiet_NaN(), 2.0), 0.0f);
}

// ---------------------------------------------------------------------------------------------------------------------
// Writing and reading

TEST(ImageIo, ExrRoundTripKeepsChannelsAndMetadata) {
    const fs::path dir = testDirectory("exr_round_trip");
    const std::vector<std::string> channels = {"R",          "G",          "B",         "variance.R",
                                               "variance.G", "variance.B", "ratio.num", "ratio.den"};
    Image image(7, 5, channels);
    for (std::size_t i = 0; i < image.size(); ++i) {
        image.data()[i] = (static_cast<float>(i) * 0.37f - 3.0f) * std::pow(10.0f, static_cast<float>(i % 9) - 4.0f);
    }
    // Values that a lossy or converting path would not keep.
    image.at(0, 0, 0) = -0.0f;
    image.at(1, 0, 0) = std::numeric_limits<float>::denorm_min();
    image.at(2, 0, 0) = std::numeric_limits<float>::max();
    image.at(3, 0, 0) = std::numeric_limits<float>::infinity();
    image.at(4, 0, 0) = 1.0f / 3.0f;
    image.metadata = {{"technique", "ltsd"},
                      {"spp", "1024"},
                      {"compression", "none"},  // a standard EXR attribute name: the "tyndall:" prefix keeps them apart
                      {"parameters", R"({"sigma_s": [0.1, 0.2, 0.3]})"},
                      {"empty", ""}};

    const fs::path path = dir / "round_trip.exr";
    writeImage(image, path.string());
    EXPECT_EQ(filesIn(dir), std::vector<std::string>{"round_trip.exr"});  // the temporary was renamed

    const Image read = readImage(path.string());
    EXPECT_EQ(read.width(), 7);
    EXPECT_EQ(read.height(), 5);
    EXPECT_EQ(read.channels(), channels);
    EXPECT_EQ(read.metadata, image.metadata);
    ASSERT_EQ(read.size(), image.size());
    EXPECT_EQ(std::memcmp(read.data(), image.data(), image.size() * sizeof(float)), 0) << "floats are not bit-exact";
}

TEST(ImageIo, PngWritesExposedSrgbBytes) {
    const fs::path dir = testDirectory("png_bytes");
    Image image(4, 2, {"R", "G", "B", "variance.R"});  // the extra channel is not written
    // Linear values; with exposure 1 each is doubled, sRGB-encoded, clamped and rounded to 8 bits:
    //   0      -> 0                                                   -> 0
    //   0.001  -> 0.002 (linear segment): 12.92 * 0.002 = 0.02584     -> 6.589 -> 7
    //   0.05   -> 0.1:  1.055 * 0.1^(1/2.4) - 0.055 = 0.349190        -> 89.04 -> 89
    //   0.1    -> 0.2:  0.484529                                      -> 123.55 -> 124
    //   0.25   -> 0.5:  0.735357                                      -> 187.52 -> 188
    //   0.4    -> 0.8:  0.906332                                      -> 231.11 -> 231
    //   0.5    -> 1.0                                                 -> 255
    //   2.0    -> 4.0, clamped                                        -> 255
    //   -1     -> -2, clamped                                         -> 0
    const float values[8][3] = {{0.0f, 0.001f, 0.05f}, {0.1f, 0.25f, 0.4f}, {0.5f, 2.0f, -1.0f},  {0.25f, 0.0f, 0.5f},
                                {0.4f, 0.4f, 0.4f},    {2.0f, 0.1f, 0.0f},  {0.05f, 0.5f, 0.25f}, {0.001f, 0.0f, 2.0f}};
    const int expected[8][3] = {{0, 7, 89},      {124, 188, 231}, {255, 255, 0},  {188, 0, 255},
                                {231, 231, 231}, {255, 124, 0},   {89, 255, 188}, {7, 0, 255}};
    for (int p = 0; p < 8; ++p) {
        for (int c = 0; c < 3; ++c)
            image.at(p % 4, p / 4, c) = values[p][c];
        image.at(p % 4, p / 4, 3) = 0.75f;
    }

    const fs::path path = dir / "exposed.png";
    writeImage(image, path.string(), 1.0);
    const Image read = readImage(path.string());
    ASSERT_EQ(read.width(), 4);
    ASSERT_EQ(read.height(), 2);
    ASSERT_EQ(read.channels(), (std::vector<std::string>{"R", "G", "B"}));
    for (int p = 0; p < 8; ++p) {
        for (int c = 0; c < 3; ++c) {
            EXPECT_EQ(byteOf(read.at(p % 4, p / 4, c)), expected[p][c]) << "pixel " << p << " channel " << c;
        }
    }
}

TEST(ImageIo, OverwritesAnExistingFile) {
    const fs::path dir = testDirectory("overwrite");
    const fs::path path = dir / "out.exr";
    Image image = Image::rgb(2, 2);
    writeImage(image, path.string());
    image.at(1, 1, 2) = 5.0f;
    writeImage(image, path.string());
    EXPECT_EQ(readImage(path.string()).at(1, 1, 2), 5.0f);
    EXPECT_EQ(filesIn(dir), std::vector<std::string>{"out.exr"});
}

TEST(ImageIo, MissingDirectoryThrowsAndLeavesNoFile) {
    const fs::path dir = testDirectory("missing_directory");
    const fs::path path = dir / "no-such-directory" / "out.exr";
    try {
        writeImage(Image::rgb(2, 2), path.string());
        FAIL() << "expected InputError";
    } catch (const InputError& e) {
        EXPECT_EQ(e.where().file, path.string());
        EXPECT_NE(std::string(e.what()).find("does not exist"), std::string::npos) << e.what();
    }
    EXPECT_FALSE(fs::exists(dir / "no-such-directory"));
    EXPECT_TRUE(filesIn(dir).empty());
}

TEST(ImageIo, FailedRenameRemovesTheTemporary) {
    // The target is a directory, so writing the temporary succeeds and renaming it over the target fails.
    const fs::path dir = testDirectory("failed_rename");
    fs::create_directory(dir / "taken.exr");
    EXPECT_THROW(writeImage(Image::rgb(2, 2), (dir / "taken.exr").string()), InputError);
    EXPECT_EQ(filesIn(dir), std::vector<std::string>{"taken.exr"});
    EXPECT_TRUE(fs::is_directory(dir / "taken.exr"));
}

TEST(ImageIo, UnknownExtensionListsTheAllowedOnes) {
    const fs::path dir = testDirectory("unknown_extension");
    const fs::path path = dir / "out.tiff";
    try {
        writeImage(Image::rgb(2, 2), path.string());
        FAIL() << "expected InputError";
    } catch (const InputError& e) {
        const std::string message = e.what();
        EXPECT_NE(message.find(path.string()), std::string::npos) << message;
        EXPECT_NE(message.find(".exr"), std::string::npos) << message;
        EXPECT_NE(message.find(".png"), std::string::npos) << message;
    }
    EXPECT_THROW(writeImage(Image::rgb(2, 2), (dir / "no_extension").string()), InputError);
    EXPECT_TRUE(filesIn(dir).empty());
}

TEST(ImageIo, PngWithoutRgbThrowsAndLeavesNoFile) {
    const fs::path dir = testDirectory("png_without_rgb");
    EXPECT_THROW(writeImage(Image(2, 2, {"Y"}), (dir / "out.png").string()), InputError);
    EXPECT_TRUE(filesIn(dir).empty());
}

TEST(ImageIo, MissingOrUnreadableInputNamesThePath) {
    const fs::path dir = testDirectory("unreadable");
    const fs::path missing = dir / "missing.exr";
    try {
        (void)readImage(missing.string());
        FAIL() << "expected InputError";
    } catch (const InputError& e) {
        EXPECT_EQ(e.where().file, missing.string());
    }

    const fs::path garbage = dir / "garbage.exr";
    std::ofstream(garbage) << "this is not an OpenEXR file\n";
    try {
        (void)readImage(garbage.string());
        FAIL() << "expected InputError";
    } catch (const InputError& e) {
        EXPECT_EQ(e.where().file, garbage.string());
    }
}

// Files written by other programs: OpenEXR's own writer (half floats, tiles, a data window away from the origin,
// unsorted channel names) and libpng's (grey, 16 bits, alpha).
TEST(ImageIo, ReadsTiledHalfExrWithAnOffsetDataWindow) {
    const fs::path path = testDirectory("tiled_half") / "tiled.exr";
    const Imath::Box2i display({0, 0}, {9, 9}), window({3, 2}, {7, 4});  // 5 x 3 pixels at (3, 2)
    Imf::Header header(display, window);
    header.channels().insert("Z", Imf::Channel(Imf::HALF));
    header.channels().insert("A", Imf::Channel(Imf::HALF));
    header.setTileDescription(Imf::TileDescription(2, 2));
    std::vector<half> z(15), a(15);
    for (int i = 0; i < 15; ++i) {
        z[std::size_t(i)] = half(0.25f * float(i));
        a[std::size_t(i)] = half(-1.0f - float(i));
    }
    Imf::FrameBuffer frame;
    frame.insert("Z", Imf::Slice::Make(Imf::HALF, z.data(), window));
    frame.insert("A", Imf::Slice::Make(Imf::HALF, a.data(), window));
    {
        Imf::TiledOutputFile file(path.c_str(), header);
        file.setFrameBuffer(frame);
        file.writeTiles(0, file.numXTiles() - 1, 0, file.numYTiles() - 1);
    }
    const Image read = readImage(path.string());
    ASSERT_EQ(read.width(), 5);
    ASSERT_EQ(read.height(), 3);
    ASSERT_EQ(read.channels(), (std::vector<std::string>{"A", "Z"}));  // the file's (sorted) order: no order recorded
    for (int i = 0; i < 15; ++i) {
        EXPECT_EQ(read.at(i % 5, i / 5, 1), 0.25f * float(i)) << i;
        EXPECT_EQ(read.at(i % 5, i / 5, 0), -1.0f - float(i)) << i;
    }
}

TEST(ImageIo, RefusesSubsampledAndOversizedExr) {
    const fs::path dir = testDirectory("refused_exr");
    {
        Imf::Header header(4, 4);
        header.channels().insert("Y", Imf::Channel(Imf::FLOAT));
        header.channels().insert("BY", Imf::Channel(Imf::FLOAT, 2, 2));
        std::vector<float> y(16), by(4);
        Imf::FrameBuffer frame;
        frame.insert("Y", Imf::Slice(Imf::FLOAT, reinterpret_cast<char*>(y.data()), 4, 16));
        frame.insert("BY", Imf::Slice(Imf::FLOAT, reinterpret_cast<char*>(by.data()), 4, 8, 2, 2));
        Imf::OutputFile file((dir / "subsampled.exr").c_str(), header);
        file.setFrameBuffer(frame);
        file.writePixels(4);
    }
    {
        // A header that asks for 2^32 pixels; no pixel is written, and none must be allocated on reading.
        Imf::Header header(65536, 65536);
        header.channels().insert("Y", Imf::Channel(Imf::HALF));
        Imf::OutputFile file((dir / "huge.exr").c_str(), header);
    }
    const auto refusal = [](const fs::path& path) {
        try {
            (void)readImage(path.string());
        } catch (const InputError& e) {
            EXPECT_EQ(e.where().file, path.string());
            return std::string(e.what());
        }
        return std::string("(read)");
    };
    EXPECT_NE(refusal(dir / "subsampled.exr").find("channel \"BY\" is subsampled"), std::string::npos)
        << refusal(dir / "subsampled.exr");
    EXPECT_NE(refusal(dir / "huge.exr").find("65536 x 65536 pixels of 1 channels; at most 268435456 values"),
              std::string::npos)
        << refusal(dir / "huge.exr");
}

TEST(ImageIo, ReadsGreyAndSixteenBitPngs) {
    const fs::path dir = testDirectory("png_formats");
    const auto writePng = [&](const std::string& name, png_uint_32 format, const void* pixels) {
        png_image png{};
        png.version = PNG_IMAGE_VERSION;
        png.width = 3;
        png.height = 2;
        png.format = format;
        ASSERT_TRUE(png_image_write_to_file(&png, (dir / name).c_str(), 0, pixels, 0, nullptr)) << png.message;
    };
    const std::uint8_t grey[6] = {0, 51, 102, 153, 204, 255};
    writePng("grey.png", PNG_FORMAT_GRAY, grey);
    const Image g = readImage((dir / "grey.png").string());
    ASSERT_EQ(g.channels(), std::vector<std::string>{"Y"});
    for (int i = 0; i < 6; ++i)
        EXPECT_EQ(byteOf(g.at(i % 3, i / 3, 0)), grey[i]);

    // 16 bits with alpha: the stored values / 65535, as they are (whatever transfer function the file declares).
    std::vector<std::uint16_t> rgba(24);
    for (std::size_t i = 0; i < rgba.size(); ++i)
        rgba[i] = static_cast<std::uint16_t>(i % 4 == 3 ? 65535 : i * 2000);
    writePng("rgba16.png", PNG_FORMAT_LINEAR_RGB_ALPHA, rgba.data());
    const Image c = readImage((dir / "rgba16.png").string());
    ASSERT_EQ(c.channels(), (std::vector<std::string>{"R", "G", "B", "A"}));
    for (int p = 0; p < 6; ++p) {
        EXPECT_EQ(c.at(p % 3, p / 3, 3), 1.0f);
        for (int ch = 0; ch < 3; ++ch)
            EXPECT_EQ(c.at(p % 3, p / 3, ch), float(rgba[std::size_t(4 * p + ch)]) / 65535.0f) << p << " " << ch;
    }
}

TEST(ImageIo, TellsFormatsByContentAndNamesOtherFiles) {
    const fs::path dir = testDirectory("by_content");
    Image image = Image::rgb(3, 2);
    image.at(2, 1, 0) = 0.5f;
    writeImage(image, (dir / "real.exr").string());
    fs::copy_file(dir / "real.exr", dir / "named.png");  // an EXR named .png is read as the EXR it is
    EXPECT_EQ(readImage((dir / "named.png").string()).at(2, 1, 0), 0.5f);

    std::ofstream(dir / "photo.jpg", std::ios::binary) << std::string("\xff\xd8\xff\xe0\x00\x10JFIF", 10);
    try {
        (void)readImage((dir / "photo.jpg").string());
        FAIL() << "expected InputError";
    } catch (const InputError& e) {
        EXPECT_EQ(e.where().file, (dir / "photo.jpg").string());
        EXPECT_NE(std::string(e.what()).find("neither an OpenEXR nor a PNG file"), std::string::npos) << e.what();
    }
    // A damaged EXR (its pixels cut off): OpenEXR's error, with the path.
    std::ifstream in(dir / "real.exr", std::ios::binary);
    const std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    std::ofstream(dir / "cut.exr", std::ios::binary) << bytes.substr(0, bytes.size() - 20);
    EXPECT_THROW((void)readImage((dir / "cut.exr").string()), InputError);
}

}  // namespace
}  // namespace tyndall

// ---------------------------------------------------------------------------------------------------------------------
// Display transforms (tonemap.h)

TEST(Tonemap, SrgbIsTheClampedTransferFunction) {
    for (float v : {0.0f, 0.001f, 0.0031308f, 0.18f, 0.5f, 1.0f, 3.0f}) {
        const auto d = tyndall::tonemapRgb(v, v, v, 1.0, tyndall::Tonemap::Srgb);
        EXPECT_FLOAT_EQ(d[0], tyndall::tonemap(v, 1.0)) << v;
    }
    const auto nan = tyndall::tonemapRgb(std::nanf(""), -1.0f, 0.5f, 0.0, tyndall::Tonemap::Srgb);
    EXPECT_EQ(nan[0], 0.0f);
    EXPECT_EQ(nan[1], 0.0f);
}

// Reinhard's L / (1 + L) on luminance: luminance 1 becomes 1/2 and every channel is scaled alike (hue kept).
TEST(Tonemap, ReinhardCompressesLuminanceAndKeepsChannelRatios) {
    const float r = 2.0f, g = 0.8f, b = 0.3f;
    const float l = 0.2126f * r + 0.7152f * g + 0.0722f * b;
    const auto d = tyndall::tonemapRgb(r / l, g / l, b / l, 0.0, tyndall::Tonemap::Reinhard);
    for (int c = 0; c < 3; ++c) {
        const float expected = std::clamp(tyndall::srgbEncode(0.5f * std::array<float, 3>{r, g, b}[std::size_t(c)] / l),
                                          0.0f, 1.0f);
        EXPECT_NEAR(d[std::size_t(c)], expected, 1e-6f) << c;
    }
    // Never above 1 however bright, and monotone in the luminance.
    float last = 0.0f;
    for (float v = 0.01f; v < 1e4f; v *= 1.7f) {
        const float y = tyndall::tonemapRgb(v, v, v, 0.0, tyndall::Tonemap::Reinhard)[1];
        EXPECT_LE(y, 1.0f);
        EXPECT_GE(y, last);
        last = y;
    }
}

// Narkowicz's fit: 0 at 0, increases until it saturates at 1 (about 16 times mid grey's exposure); mid grey 0.18 lands near his curve's 0.18 * 0.6 input value.
TEST(Tonemap, AcesFitIsMonotoneAndSaturates) {
    EXPECT_EQ(tyndall::tonemapRgb(0.0f, 0.0f, 0.0f, 0.0, tyndall::Tonemap::Aces)[0], 0.0f);
    EXPECT_FLOAT_EQ(tyndall::tonemapRgb(1e6f, 1e6f, 1e6f, 0.0, tyndall::Tonemap::Aces)[0], 1.0f);
    float last = -1.0f;
    for (float v = 0.001f; v < 100.0f; v *= 1.3f) {
        const float y = tyndall::tonemapRgb(v, v, v, 0.0, tyndall::Tonemap::Aces)[0];
        EXPECT_TRUE(y > last || (y == 1.0f && last == 1.0f)) << v << ": " << y << " after " << last;
        last = y;
    }
    const float x = 0.18f * 0.6f;
    const float fit = x * (2.51f * x + 0.03f) / (x * (2.43f * x + 0.59f) + 0.14f);
    EXPECT_NEAR(tyndall::tonemapRgb(0.18f, 0.18f, 0.18f, 0.0, tyndall::Tonemap::Aces)[0], tyndall::srgbEncode(fit), 1e-6f);
}

// False colour: log2 luminance after exposure, -10 EV at viridis(0), +2 EV at viridis(1), -4 EV half way.
TEST(Tonemap, FalseColourMapsLogLuminanceToViridis) {
    auto shown = [](double t) {
        const tyndall::Rgb c = tyndall::viridis(t);
        return std::array<float, 3>{tyndall::srgbEncode(float(c.r)), tyndall::srgbEncode(float(c.g)),
                                    tyndall::srgbEncode(float(c.b))};
    };
    const std::pair<float, double> cases[] = {{std::exp2(-10.0f), 0.0}, {std::exp2(2.0f), 1.0}, {std::exp2(-4.0f), 0.5},
                                              {0.0f, 0.0},              {1e9f, 1.0}};
    for (auto [l, t] : cases) {
        // Exposure +1 EV applied to half the luminance.
        const auto d = tyndall::tonemapRgb(l / 2, l / 2, l / 2, 1.0, tyndall::Tonemap::FalseColour);
        const auto e = shown(t);
        for (int c = 0; c < 3; ++c) EXPECT_NEAR(d[std::size_t(c)], e[std::size_t(c)], 1e-5f) << l << " channel " << c;
    }
}

TEST(Tonemap, NamesRoundTripAndAnUnknownOneIsRefused) {
    for (std::size_t i = 0; i < tyndall::tonemapNames().size(); ++i)
        EXPECT_EQ(int(tyndall::tonemapFromName(tyndall::tonemapNames()[i], "x")), int(i));
    try {
        tyndall::tonemapFromName("filmic", "views.a.tonemap");
        FAIL() << "accepted an unknown operator";
    } catch (const tyndall::InputError& e) {
        EXPECT_NE(std::string(e.what()).find("views.a.tonemap"), std::string::npos) << e.what();
        EXPECT_NE(std::string(e.what()).find("srgb, reinhard, aces, falsecolour"), std::string::npos) << e.what();
    }
}
