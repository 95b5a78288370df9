// Colour management through OpenColorIO (docs/colour.md): the config (--ocio, else $OCIO, else Tyndall's shipped
// config, else OpenColorIO's raw config), its displays and views, the display transforms that turn linear renders into
// what a monitor shows, and the colour spaces of image files. OpenColorIO stays behind this header.
#pragma once

#include "tyndall/image/image.h"
#include "tyndall/image/tonemap.h"

#include <array>
#include <cstddef>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

namespace tyndall {

class ColourConfig {
public:
    // The config Tyndall uses: `path` when not empty (given by the option `field`), else $OCIO when set, else the
    // shipped config (shippedConfigPath()), else OpenColorIO's raw config. One that cannot be read or does not
    // validate is passed over for the next, with a line in warnings() naming the file, where it came from and
    // OpenColorIO's reason.
    static std::shared_ptr<const ColourConfig> load(const std::string& path = "", const std::string& field = "--ocio");
    // One file, read and validated. Throws InputError naming the file and OpenColorIO's reason.
    static std::shared_ptr<const ColourConfig> fromFile(const std::string& path, const std::string& origin = "file");
    // OpenColorIO's raw config: one display, sRGB, with the one view Raw (values as they are).
    static std::shared_ptr<const ColourConfig> raw();
    // resourceRoot() / "colour" / "tyndall.ocio".
    static std::filesystem::path shippedConfigPath();

    const std::string& file() const { return file_; }      // empty for the raw config
    const std::string& origin() const { return origin_; }  // "--ocio", "$OCIO", "shipped", "raw", "file"
    const std::vector<std::string>& warnings() const { return warnings_; }
    std::string describe()
        const;  // "the shipped config /usr/share/tyndall/colour/tyndall.ocio", "OpenColorIO's raw config"

    std::vector<std::string> displays() const;
    std::vector<std::string> views(const std::string& display) const;
    std::string defaultDisplay() const;
    std::string defaultView(const std::string& display) const;

    // The scene-linear working space (the scene_linear role, else default, else the first colour space).
    const std::string& sceneLinear() const { return sceneLinear_; }
    bool hasColourSpace(const std::string& name) const;
    // The colour space of an image file by the config's file rules (its name's extension), or empty when the config
    // has no rules beyond its default one and so cannot tell.
    std::string colourSpaceOfFile(const std::string& path) const;
    // R, G, B of `image` (the first three channels when it has no R, G, B) from `colourSpace` to the scene-linear
    // space, in place. Throws InputError naming the colour space and the config for an unknown one.
    void toSceneLinear(Image& image, const std::string& colourSpace) const;

    struct State;  // OpenColorIO's objects

private:
    ColourConfig() = default;
    std::shared_ptr<const State> state_;
    std::string file_, origin_, sceneLinear_;
    std::vector<std::string> warnings_;
    friend class DisplayTransform;
};

// How linear values are shown: an OpenColorIO display and view of a config, or one of Tyndall's own operators
// (tonemap.h: sRGB, Reinhard, the ACES fit, false colour). The exposure (2^EV) is applied first, outside OpenColorIO,
// so that changing it rebuilds nothing.
class DisplayTransform {
public:
    DisplayTransform(Tonemap op = Tonemap::Srgb);  // NOLINT(google-explicit-constructor): Tyndall's own operator
    // Throws InputError naming the display or view and listing those the config has.
    DisplayTransform(std::shared_ptr<const ColourConfig> config, const std::string& display, const std::string& view);

    bool isOcio() const { return config_ != nullptr; }
    Tonemap tonemap() const { return op_; }  // Tyndall's operator (not used when isOcio())
    bool falseColour() const { return !isOcio() && op_ == Tonemap::FalseColour; }
    const std::shared_ptr<const ColourConfig>& config() const { return config_; }
    const std::string& display() const { return display_; }
    const std::string& view() const { return view_; }
    // "sRGB / Standard" for a display and view, Tyndall's operator's name ("falsecolour") otherwise.
    std::string name() const;

    // Display values in [0, 1] of `pixels` interleaved linear RGB triples, in place, after 2^exposure (NaN and
    // infinities count as 0).
    void apply(float* rgb, std::size_t pixels, double exposure) const;
    std::array<float, 3> apply(float r, float g, float b, double exposure) const;

    // The same operator, or the same config, display and view.
    bool operator==(const DisplayTransform& other) const;

    struct Processor;

private:
    Tonemap op_ = Tonemap::Srgb;
    std::shared_ptr<const ColourConfig> config_;
    std::string display_, view_;
    std::shared_ptr<const Processor> processor_;
};

// The display transform of the CLI's options: Tyndall's operator when `tonemap` is given, else `display` and `view` of
// `config` (empty: the config's default display, and that display's default view). InputError naming the option.
DisplayTransform displayTransformFromOptions(const std::shared_ptr<const ColourConfig>& config,
                                             const std::string& tonemap, const std::string& display,
                                             const std::string& view);

}  // namespace tyndall
