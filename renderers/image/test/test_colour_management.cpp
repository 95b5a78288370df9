// Colour management through OpenColorIO (issue 35): the shipped config, the order in which configs are chosen and
// passed over, the display transforms against their closed forms, the colour spaces of files, and PNGs that record
// how they were shown.
#include "tyndall/core/error.h"
#include "tyndall/image/colour_management.h"
#include "tyndall/image/image_io.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <string>
#include <vector>

namespace tyndall {
namespace {

const std::string kData = TYNDALL_SOURCE_DIR "/tests/data/ocio/";

// $OCIO for the length of a scope (unset when `value` is empty), restored after.
class ScopedOcio {
public:
    explicit ScopedOcio(const std::string& value) {
        if (const char* old = std::getenv("OCIO")) old_ = old, had_ = true;
        if (value.empty())
            unsetenv("OCIO");
        else
            setenv("OCIO", value.c_str(), 1);
    }
    ~ScopedOcio() {
        if (had_)
            setenv("OCIO", old_.c_str(), 1);
        else
            unsetenv("OCIO");
    }

private:
    std::string old_;
    bool had_ = false;
};

std::shared_ptr<const ColourConfig> shipped() {
    return ColourConfig::fromFile(ColourConfig::shippedConfigPath().string(), "shipped");
}

double srgbCurve(double linear) {
    const double x = std::clamp(linear, 0.0, 1.0);
    return x <= 0.0031308 ? 12.92 * x : 1.055 * std::pow(x, 1.0 / 2.4) - 0.055;
}

TEST(ColourManagement, TheShippedConfigLoadsAndValidates) {
    const auto config = shipped();
    EXPECT_EQ(config->displays(), (std::vector<std::string>{"sRGB", "Rec.1886"}));
    for (const std::string& display : config->displays())
        EXPECT_EQ(config->views(display), (std::vector<std::string>{"Standard", "ACES 1.0 - SDR Video", "Raw"}));
    EXPECT_EQ(config->defaultDisplay(), "sRGB");
    EXPECT_EQ(config->defaultView("sRGB"), "Standard");
    EXPECT_EQ(config->sceneLinear(), "Linear Rec.709 (sRGB)");
    EXPECT_TRUE(config->warnings().empty());
    // Without $OCIO and --ocio, load() takes it, quietly.
    const ScopedOcio none("");
    const auto loaded = ColourConfig::load();
    EXPECT_EQ(loaded->origin(), "shipped");
    EXPECT_TRUE(loaded->warnings().empty());
}

// The sRGB display's Standard view is the closed-form sRGB curve of the exposed value (to 1e-4, the bound;
// OpenColorIO's CPU path evaluates the power in float), and so is Tyndall's own sRGB operator.
TEST(ColourManagement, TheSrgbDisplayIsTheClosedFormCurve) {
    const DisplayTransform standard(shipped(), "sRGB", "Standard");
    const DisplayTransform ours(Tonemap::Srgb);
    double worst = 0.0;
    for (int i = 0; i <= 2000; ++i) {
        const float v = float(i) / 1600.0f;  // beyond 1 too: clipped
        for (const double exposure : {0.0, -1.5, 2.0}) {
            const double expected = srgbCurve(v * std::exp2(exposure));
            const auto d = standard.apply(v, 0.5f * v, 0.25f * v, exposure);
            worst = std::max(worst, std::abs(d[0] - expected));
            EXPECT_NEAR(d[1], srgbCurve(0.5 * v * std::exp2(exposure)), 1e-4) << v;
            EXPECT_NEAR(d[2], srgbCurve(0.25 * v * std::exp2(exposure)), 1e-4) << v;
            EXPECT_NEAR(ours.apply(v, v, v, exposure)[0], expected, 1e-5);
        }
    }
    EXPECT_LT(worst, 1e-4);
    // Not a number and infinities show as black, as with Tyndall's operators.
    const auto bad = standard.apply(std::nanf(""), INFINITY, -INFINITY, 0.0);
    EXPECT_EQ(bad, (std::array<float, 3>{0.0f, 0.0f, 0.0f}));
}

// Rec.1886 with a black level of 0 is a pure 2.4 power; Raw leaves the values as they are (clamped to the display).
TEST(ColourManagement, Rec1886AndRawAgainstTheirClosedForms) {
    const auto config = shipped();
    const DisplayTransform rec1886(config, "Rec.1886", "Standard"), raw(config, "sRGB", "Raw");
    for (int i = 0; i <= 100; ++i) {
        const float v = float(i) / 100.0f;
        EXPECT_NEAR(rec1886.apply(v, v, v, 0.0)[0], std::pow(v, 1.0 / 2.4), 1e-4) << v;
        EXPECT_NEAR(raw.apply(v, v, v, 0.0)[1], v, 1e-6) << v;
    }
    EXPECT_EQ(raw.apply(2.0f, -1.0f, 0.5f, 0.0), (std::array<float, 3>{1.0f, 0.0f, 0.5f}));
}

// The ACES view is OpenColorIO's built-in output transform: a tone curve, not a clip. Mid grey (0.18) lands near
// 10 % of the display's white (about 0.35 on the sRGB curve), it rises monotonically (strictly from 4 stops below
// mid grey; the RRT's toe takes the deep shadows to black), and highlights that Standard clips keep their gradation
// below 1.
TEST(ColourManagement, TheAcesViewToneMaps) {
    const DisplayTransform aces(shipped(), "sRGB", "ACES 1.0 - SDR Video");
    const float grey = aces.apply(0.18f, 0.18f, 0.18f, 0.0)[1];
    EXPECT_GT(grey, 0.30f);
    EXPECT_LT(grey, 0.42f);
    std::printf("ACES 1.0 SDR video on sRGB: mid grey 0.18 -> %.4f\n", grey);
    float previous = -1.0f;
    for (double stops = -8.0; stops <= 6.0; stops += 0.5) {
        const float v = aces.apply(0.18f, 0.18f, 0.18f, stops)[1];
        EXPECT_GE(v, previous) << stops;
        if (stops >= -4.0) {
            EXPECT_GT(v, previous) << stops;
        }
        previous = v;
    }
    EXPECT_LT(aces.apply(4.0f, 4.0f, 4.0f, 0.0)[1], aces.apply(16.0f, 16.0f, 16.0f, 0.0)[1]);
    EXPECT_LT(aces.apply(16.0f, 16.0f, 16.0f, 0.0)[1], 1.0f);
    EXPECT_LT(aces.apply(0.0f, 0.0f, 0.0f, 0.0)[1], 0.01f);
}

// --ocio, then $OCIO, then the shipped config, then OpenColorIO's raw one; each config passed over is said, with its
// file and OpenColorIO's reason.
TEST(ColourManagement, ConfigsAreChosenInOrderAndPassedOverWithTheReason) {
    {
        const ScopedOcio ocio(kData + "cinema.ocio");
        const auto config = ColourConfig::load();
        EXPECT_EQ(config->origin(), "$OCIO");
        EXPECT_EQ(config->displays(), (std::vector<std::string>{"Cinema"}));
        EXPECT_EQ(config->views("Cinema"), (std::vector<std::string>{"Film", "Raw"}));
        EXPECT_TRUE(config->warnings().empty());
        // --ocio comes first.
        const auto chosen = ColourConfig::load(ColourConfig::shippedConfigPath().string());
        EXPECT_EQ(chosen->origin(), "--ocio");
        EXPECT_EQ(chosen->displays().front(), "sRGB");
    }
    {
        const ScopedOcio ocio(kData + "broken.ocio");
        const auto config = ColourConfig::load(kData + "nowhere.ocio");
        EXPECT_EQ(config->origin(), "shipped");
        ASSERT_EQ(config->warnings().size(), 2u);
        EXPECT_NE(config->warnings()[0].find("--ocio"), std::string::npos) << config->warnings()[0];
        EXPECT_NE(config->warnings()[0].find("nowhere.ocio"), std::string::npos) << config->warnings()[0];
        EXPECT_NE(config->warnings()[0].find("no such file"), std::string::npos) << config->warnings()[0];
        EXPECT_NE(config->warnings()[1].find("$OCIO"), std::string::npos) << config->warnings()[1];
        EXPECT_NE(config->warnings()[1].find("broken.ocio"), std::string::npos) << config->warnings()[1];
        EXPECT_NE(config->warnings()[1].find("'missing'"), std::string::npos) << config->warnings()[1];  // OCIO's
        EXPECT_NE(config->warnings()[1].find("using the shipped config"), std::string::npos);
    }
    {
        // Without the shipped config (a resource root that lacks it): OpenColorIO's raw config, one sRGB / Raw.
        const ScopedOcio ocio("");
        setenv("TYNDALL_ROOT", TYNDALL_TEST_TMP, 1);
        const auto config = ColourConfig::load();
        unsetenv("TYNDALL_ROOT");
        EXPECT_EQ(config->origin(), "raw");
        EXPECT_EQ(config->describe(), "OpenColorIO's raw config");
        ASSERT_EQ(config->warnings().size(), 1u);
        EXPECT_NE(config->warnings()[0].find("tyndall.ocio"), std::string::npos) << config->warnings()[0];
        const DisplayTransform raw(config, config->defaultDisplay(), config->defaultView(config->defaultDisplay()));
        EXPECT_NEAR(raw.apply(0.25f, 0.5f, 0.75f, 0.0)[2], 0.75f, 1e-6);
    }
    EXPECT_THROW(ColourConfig::fromFile(kData + "broken.ocio"), InputError);
}

TEST(ColourManagement, OptionsNameWhatIsWrongAndWhatIsAllowed) {
    const auto config = shipped();
    const DisplayTransform byDefault = displayTransformFromOptions(config, "", "", "");
    EXPECT_EQ(byDefault.name(), "sRGB / Standard");
    EXPECT_EQ(displayTransformFromOptions(config, "", "Rec.1886", "").name(), "Rec.1886 / Standard");
    EXPECT_EQ(displayTransformFromOptions(config, "reinhard", "", "").name(), "reinhard");
    EXPECT_FALSE(displayTransformFromOptions(nullptr, "aces", "", "").isOcio());
    const auto refusal = [&](const std::string& tonemap, const std::string& display, const std::string& view) {
        try {
            displayTransformFromOptions(config, tonemap, display, view);
        } catch (const InputError& e) {
            return std::string(e.what());
        }
        return std::string("accepted");
    };
    EXPECT_NE(refusal("", "P3", "").find("--display"), std::string::npos);
    EXPECT_NE(refusal("", "P3", "").find("no display \"P3\""), std::string::npos);
    EXPECT_NE(refusal("", "P3", "").find("\"sRGB\", \"Rec.1886\""), std::string::npos);
    EXPECT_NE(refusal("", "sRGB", "Filmic").find("--ocio-view"), std::string::npos);
    EXPECT_NE(refusal("", "sRGB", "Filmic").find("\"Standard\", \"ACES 1.0 - SDR Video\", \"Raw\""), std::string::npos);
    EXPECT_NE(refusal("aces", "sRGB", "").find("one or the other"), std::string::npos);
    EXPECT_NE(refusal("filmic", "", "").find("allowed: srgb, reinhard, aces, falsecolour"), std::string::npos);
}

// PNG, JPEG, TIFF, BMP and TGA are sRGB by the shipped config's file rules, the rest its default (the config does not
// say: empty); converting sRGB - Texture to the working space is the sRGB curve's inverse.
TEST(ColourManagement, FileRulesAndInputColourSpaces) {
    const auto config = shipped();
    for (const char* name : {"a.png", "b.PNG", "c.jpg", "d.jpeg", "e.tif", "f.tiff", "g.bmp", "h.tga"})
        EXPECT_EQ(config->colourSpaceOfFile(std::string("/x/") + name), "sRGB - Texture") << name;
    for (const char* name : {"a.exr", "b.hdr", "c.pfm"})
        EXPECT_EQ(config->colourSpaceOfFile(name), "") << name;
    EXPECT_EQ(ColourConfig::fromFile(kData + "cinema.ocio")->colourSpaceOfFile("a.png"), "");
    Image image = Image::rgb(101, 1);
    for (int x = 0; x <= 100; ++x)
        for (int c = 0; c < 3; ++c)
            image.at(x, 0, c) = float(x) / 100.0f;
    config->toSceneLinear(image, "sRGB - Texture");
    for (int x = 0; x <= 100; ++x)
        EXPECT_NEAR(image.at(x, 0, 1), srgbDecode(float(x) / 100.0f), 1e-5) << x;
    EXPECT_THROW(config->toSceneLinear(image, "Kodak 2383"), InputError);
}

// A PNG through a display and view holds the transform's values and says how it was made (its text chunks come back
// as metadata), beside the image's own metadata.
TEST(ColourManagement, PngsRecordTheirDisplayTransform) {
    const std::filesystem::path dir = std::filesystem::path(TYNDALL_TEST_TMP) / "colour";
    std::filesystem::create_directories(dir);
    Image image = Image::rgb(8, 4);
    for (int y = 0; y < 4; ++y)
        for (int x = 0; x < 8; ++x)
            for (int c = 0; c < 3; ++c)
                image.at(x, y, c) = 0.05f * float(x + y + c);
    image.metadata["technique"] = "ltsd";
    image.metadata["parameters"] = std::string(3000, 'p');  // long: compressed (zTXt)
    const auto config = shipped();
    const DisplayTransform aces(config, "sRGB", "ACES 1.0 - SDR Video");
    const std::string path = (dir / "aces.png").string();
    writeImage(image, path, 1.0, aces);
    const Image back = readImage(path);
    EXPECT_EQ(back.metadata.at("display"), "sRGB");
    EXPECT_EQ(back.metadata.at("view"), "ACES 1.0 - SDR Video");
    EXPECT_EQ(back.metadata.at("ocioConfig"), ColourConfig::shippedConfigPath().string());
    EXPECT_EQ(std::stod(back.metadata.at("displayExposure")), 1.0);
    EXPECT_EQ(back.metadata.at("technique"), "ltsd");
    EXPECT_EQ(back.metadata.at("parameters"), std::string(3000, 'p'));
    EXPECT_EQ(back.metadata.count("tonemap"), 0u);
    for (int y = 0; y < 4; ++y)
        for (int x = 0; x < 8; ++x) {
            const auto d = aces.apply(image.at(x, y, 0), image.at(x, y, 1), image.at(x, y, 2), 1.0);
            for (int c = 0; c < 3; ++c)
                EXPECT_NEAR(back.at(x, y, c), std::round(d[std::size_t(c)] * 255.0f) / 255.0f, 1e-6);
        }
    writeImage(image, (dir / "ours.png").string(), 0.0, Tonemap::FalseColour);
    const Image ours = readImage((dir / "ours.png").string());
    EXPECT_EQ(ours.metadata.at("tonemap"), "falsecolour");
    EXPECT_EQ(ours.metadata.count("display"), 0u);
}

}  // namespace
}  // namespace tyndall
