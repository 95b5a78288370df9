#include "tyndall/image/colour_management.h"

#include "tyndall/core/error.h"
#include "tyndall/core/resources.h"

#include <OpenColorIO/OpenColorIO.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>

namespace OCIO = OCIO_NAMESPACE;

namespace tyndall {

struct ColourConfig::State {
    OCIO::ConstConfigRcPtr config;
};

struct DisplayTransform::Processor {
    OCIO::ConstCPUProcessorRcPtr cpu;
};

namespace {

std::string joined(const std::vector<std::string>& names) {
    std::string out;
    for (const std::string& n : names)
        out += (out.empty() ? "\"" : ", \"") + n + "\"";
    return out.empty() ? "none" : out;
}

std::string originWords(const std::string& origin) {
    return origin == "$OCIO" ? "$OCIO" : origin == "shipped" ? "the shipped config" : origin;
}

}  // namespace

std::filesystem::path ColourConfig::shippedConfigPath() {
    return resourceRoot() / "colour" / "tyndall.ocio";
}

std::shared_ptr<const ColourConfig> ColourConfig::fromFile(const std::string& path, const std::string& origin) {
    std::error_code ec;
    if (!std::filesystem::is_regular_file(path, ec))
        throw InputError(InputLocation{.file = path}, "cannot read the OpenColorIO config: no such file");
    auto config = std::shared_ptr<ColourConfig>(new ColourConfig);
    try {
        OCIO::ConstConfigRcPtr c = OCIO::Config::CreateFromFile(path.c_str());
        c->validate();
        if (c->getNumDisplays() == 0) throw OCIO::Exception("the config has no displays");
        config->state_ = std::make_shared<State>(State{c});
    } catch (const OCIO::Exception& e) {
        throw InputError(InputLocation{.file = path}, std::string("not a usable OpenColorIO config: ") + e.what());
    }
    config->file_ = path;
    config->origin_ = origin;
    const OCIO::ConstConfigRcPtr& c = config->state_->config;
    for (const char* role : {OCIO::ROLE_SCENE_LINEAR, OCIO::ROLE_DEFAULT})
        if (OCIO::ConstColorSpaceRcPtr space = c->getColorSpace(role)) {
            config->sceneLinear_ = space->getName();
            break;
        }
    if (config->sceneLinear_.empty() && c->getNumColorSpaces() > 0)
        config->sceneLinear_ = c->getColorSpaceNameByIndex(0);
    return config;
}

std::shared_ptr<const ColourConfig> ColourConfig::raw() {
    auto config = std::shared_ptr<ColourConfig>(new ColourConfig);
    config->state_ = std::make_shared<State>(State{OCIO::Config::CreateRaw()});
    config->origin_ = "raw";
    config->sceneLinear_ = config->state_->config->getColorSpaceNameByIndex(0);
    return config;
}

std::shared_ptr<const ColourConfig> ColourConfig::load(const std::string& path, const std::string& field) {
    std::vector<std::string> warnings;
    std::vector<std::pair<std::string, std::string>> candidates;  // file, origin
    if (!path.empty()) candidates.emplace_back(path, field);
    if (const char* env = std::getenv("OCIO"); env && *env) candidates.emplace_back(env, "$OCIO");
    candidates.emplace_back(shippedConfigPath().string(), "shipped");
    std::shared_ptr<const ColourConfig> chosen;
    for (const auto& [file, origin] : candidates) {
        try {
            chosen = fromFile(file, origin);
            break;
        } catch (const InputError& e) {
            warnings.push_back(originWords(origin) + " (" + e.what() + ")");
        }
    }
    if (!chosen) chosen = raw();
    if (!warnings.empty()) {
        auto copy = std::make_shared<ColourConfig>(*chosen);
        for (const std::string& w : warnings)
            copy->warnings_.push_back("OpenColorIO: passed over " + w + "; using " + chosen->describe());
        chosen = copy;
    }
    return chosen;
}

std::string ColourConfig::describe() const {
    if (file_.empty()) return "OpenColorIO's raw config";
    const std::string whose = origin_ == "shipped" ? "the shipped config" : "the config";
    return whose + " " + file_ + (origin_ == "shipped" || origin_ == "file" ? "" : " (" + origin_ + ")");
}

std::vector<std::string> ColourConfig::displays() const {
    std::vector<std::string> out;
    const OCIO::ConstConfigRcPtr& c = state_->config;
    for (int i = 0; i < c->getNumDisplays(); ++i)
        out.emplace_back(c->getDisplay(i));
    return out;
}

std::vector<std::string> ColourConfig::views(const std::string& display) const {
    std::vector<std::string> out;
    const OCIO::ConstConfigRcPtr& c = state_->config;
    for (int i = 0; i < c->getNumViews(display.c_str()); ++i)
        out.emplace_back(c->getView(display.c_str(), i));
    return out;
}

std::string ColourConfig::defaultDisplay() const {
    return state_->config->getDefaultDisplay();
}

std::string ColourConfig::defaultView(const std::string& display) const {
    return state_->config->getDefaultView(display.c_str());
}

bool ColourConfig::hasColourSpace(const std::string& name) const {
    return state_->config->getColorSpace(name.c_str()) != nullptr;
}

std::string ColourConfig::colourSpaceOfFile(const std::string& path) const {
    const OCIO::ConstConfigRcPtr& c = state_->config;
    if (file_.empty()) return {};
    std::size_t rule = 0;
    const std::string space = c->getColorSpaceFromFilepath(path.c_str(), rule);
    // Only the default rule matched (or the config has only that one): the config does not say.
    if (rule + 1 >= c->getFileRules()->getNumEntries()) return {};
    return space;
}

void ColourConfig::toSceneLinear(Image& image, const std::string& colourSpace) const {
    if (!hasColourSpace(colourSpace))
        throw InputError("the colour space \"" + colourSpace + "\" is not in " + describe());
    if (colourSpace == sceneLinear_) return;
    int channels[3] = {image.channelIndex("R"), image.channelIndex("G"), image.channelIndex("B")};
    if (channels[0] < 0 || channels[1] < 0 || channels[2] < 0) channels[0] = 0, channels[1] = 1, channels[2] = 2;
    TY_CHECK(image.channelCount() >= 3, "toSceneLinear: an image of at least three channels");
    OCIO::ConstCPUProcessorRcPtr cpu;
    try {
        cpu = state_->config->getProcessor(colourSpace.c_str(), sceneLinear_.c_str())->getDefaultCPUProcessor();
    } catch (const OCIO::Exception& e) {
        throw InputError("cannot convert from \"" + colourSpace + "\" in " + describe() + ": " + e.what());
    }
    tbb::parallel_for(0, image.height(), [&](int y) {
        std::vector<float> row(std::size_t(image.width()) * 3);
        for (int x = 0; x < image.width(); ++x)
            for (int k = 0; k < 3; ++k)
                row[std::size_t(x) * 3 + std::size_t(k)] = image.at(x, y, channels[k]);
        OCIO::PackedImageDesc desc(row.data(), image.width(), 1, 3);
        cpu->apply(desc);
        for (int x = 0; x < image.width(); ++x)
            for (int k = 0; k < 3; ++k)
                image.at(x, y, channels[k]) = row[std::size_t(x) * 3 + std::size_t(k)];
    });
}

DisplayTransform::DisplayTransform(Tonemap op) : op_(op) {}

DisplayTransform::DisplayTransform(std::shared_ptr<const ColourConfig> config, const std::string& display,
                                   const std::string& view)
    : config_(std::move(config)), display_(display), view_(view) {
    TY_CHECK(config_ != nullptr, "DisplayTransform: a config");
    const std::vector<std::string> displays = config_->displays();
    if (std::find(displays.begin(), displays.end(), display) == displays.end())
        throw InputError("no display \"" + display + "\" in " + config_->describe() + " (it has " + joined(displays) +
                         ")");
    const std::vector<std::string> views = config_->views(display);
    if (std::find(views.begin(), views.end(), view) == views.end())
        throw InputError("no view \"" + view + "\" of the display \"" + display + "\" in " + config_->describe() +
                         " (it has " + joined(views) + ")");
    try {
        OCIO::DisplayViewTransformRcPtr t = OCIO::DisplayViewTransform::Create();
        t->setSrc(config_->sceneLinear().c_str());
        t->setDisplay(display.c_str());
        t->setView(view.c_str());
        auto processor = std::make_shared<Processor>();
        processor->cpu = config_->state_->config->getProcessor(t)->getDefaultCPUProcessor();
        processor_ = std::move(processor);
    } catch (const OCIO::Exception& e) {
        throw InputError("cannot build the display transform \"" + display + " / " + view + "\" of " +
                         config_->describe() + ": " + e.what());
    }
}

std::string DisplayTransform::name() const {
    return isOcio() ? display_ + " / " + view_ : tonemapNames()[std::size_t(op_)];
}

void DisplayTransform::apply(float* rgb, std::size_t pixels, double exposure) const {
    // In blocks, in parallel (OpenColorIO's CPU processor is thread-safe); a block keeps OpenColorIO's image
    // description small. Isolated: the calling thread (the studio's composer) waits only on these blocks, never
    // picking up a render's task from the shared arena meanwhile.
    constexpr std::size_t kBlock = 1 << 14;
    const float scale = float(std::exp2(exposure));
    tbb::this_task_arena::isolate([&] {
        tbb::parallel_for(std::size_t(0), (pixels + kBlock - 1) / kBlock, [&](std::size_t block) {
            float* start = rgb + 3 * block * kBlock;
            const std::size_t n = std::min(kBlock, pixels - block * kBlock);
            if (!isOcio()) {
                for (std::size_t i = 0; i < n; ++i) {
                    float* p = start + 3 * i;
                    const std::array<float, 3> d = tonemapRgb(p[0], p[1], p[2], exposure, op_);
                    p[0] = d[0], p[1] = d[1], p[2] = d[2];
                }
                return;
            }
            for (std::size_t i = 0; i < 3 * n; ++i)
                start[i] = std::isfinite(start[i]) ? start[i] * scale : 0.0f;
            OCIO::PackedImageDesc desc(start, long(n), 1, 3);
            processor_->cpu->apply(desc);
            for (std::size_t i = 0; i < 3 * n; ++i)
                start[i] = std::isnan(start[i]) ? 0.0f : std::clamp(start[i], 0.0f, 1.0f);
        });
    });
}

std::array<float, 3> DisplayTransform::apply(float r, float g, float b, double exposure) const {
    std::array<float, 3> p = {r, g, b};
    apply(p.data(), 1, exposure);
    return p;
}

bool DisplayTransform::operator==(const DisplayTransform& other) const {
    if (isOcio() != other.isOcio()) return false;
    if (!isOcio()) return op_ == other.op_;
    return config_ == other.config_ && display_ == other.display_ && view_ == other.view_;
}

DisplayTransform displayTransformFromOptions(const std::shared_ptr<const ColourConfig>& config,
                                             const std::string& tonemap, const std::string& display,
                                             const std::string& view) {
    if (!tonemap.empty()) {
        if (!display.empty() || !view.empty())
            throw InputError(
                "--tonemap chooses Tyndall's own operator; --display and --ocio-view choose OpenColorIO's: "
                "give one or the other");
        return DisplayTransform(tonemapFromName(tonemap, "--tonemap"));
    }
    TY_CHECK(config != nullptr, "displayTransformFromOptions: a config for OpenColorIO's display transforms");
    const std::string d = display.empty() ? config->defaultDisplay() : display;
    const std::vector<std::string> displays = config->displays();
    const bool known = std::find(displays.begin(), displays.end(), d) != displays.end();
    try {
        return DisplayTransform(config, d, view.empty() && known ? config->defaultView(d) : view);
    } catch (const InputError& e) {
        throw InputError(InputLocation{.field = known ? "--ocio-view" : "--display"}, e.message());
    }
}

}  // namespace tyndall
