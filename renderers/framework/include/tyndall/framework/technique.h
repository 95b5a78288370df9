// The one interface every renderer implements, the reference included (model: Falcor's RenderPass with reflect() and
// execute()). The CLI, project files and the studio reach renderers only through this interface and the registry
// (tyndall/techniques/registry.h).
#pragma once

#include "tyndall/core/params.h"
#include "tyndall/core/scene.h"
#include "tyndall/image/image.h"

#include <algorithm>
#include <atomic>
#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <vector>

namespace tyndall {

// What a technique can render. For anything it cannot, `reason` says why in words a user understands.
struct Support {
    bool supported = true;
    std::string reason;
    static Support yes() { return {}; }
    static Support no(std::string why) { return {false, std::move(why)}; }
};

struct RenderRequest {
    // spp that means "no cap": a progressive technique runs until timeLimit (never without one).
    static constexpr int kUnboundedSpp = 1 << 30;

    Scene scene;             // already narrowed to the view's part (ScenePart::apply)
    ParamSet params;         // complete and valid for the technique
    int spp = 0;             // samples per pixel to reach; 0: the technique's own default; kUnboundedSpp: no cap
    double timeLimit = 0.0;  // s of wall time; 0: no limit. A progressive technique stops at whichever comes first
    std::uint64_t seed = 1;
    int threads = 0;         // 0: all cores
    std::string projectDir;  // folder that relative paths (OBJ files, tables) resolve against
};

// Callbacks from a render, called on the rendering thread. Keep them short.
struct RenderCallbacks {
    std::function<void(double fraction)> progress;                  // in [0, 1]
    std::function<void(const Image& image, int spp)> intermediate;  // a complete image at a pass boundary
    const std::atomic<bool>* cancel = nullptr;                      // render throws Cancelled soon after it turns true
};

struct RenderResult {
    Image image;  // "R", "G", "B" and technique-specific extra channels; metadata filled by the technique
    int spp = 0;  // samples per pixel reached (1 for deterministic techniques)
    double seconds = 0.0;
};

// Per-pixel data for plots, e.g. the histogram of sampled distances and the analytic pdf (WVDS, Fig. 4-5).
struct ProbeInfo {
    std::string name;
    std::string doc;
};
struct ProbeSeries {
    std::string label;
    std::vector<double> x, y;
};
struct ProbeResult {
    std::string title, xLabel, yLabel;
    std::vector<ProbeSeries> series;
};

// For Technique::reduceForPreview: divides the integer parameter `name` by `divisor`, not below `floor` (a value
// already below it stays); true when it changed.
inline bool shrinkForPreview(ParamSet& params, const std::string& name, std::int64_t divisor, std::int64_t floor) {
    const std::int64_t value = params.getInt(name), next = std::max(std::min(value, floor), value / divisor);
    if (next == value) return false;
    params.set(name, next);
    return true;
}

class Technique {
public:
    virtual ~Technique() = default;

    virtual std::string name() const = 0;         // registry key, e.g. "reference"
    virtual std::string displayName() const = 0;  // for labels, e.g. "Reference (path traced)"
    // The label of a view rendered with `params`: the display name, and what of the parameters changes what the image
    // is (LTSD: its shadows).
    virtual std::string labelFor(const ParamSet& params) const {
        (void)params;
        return displayName();
    }
    virtual std::vector<ParamInfo> parameters() const = 0;
    ParamSet defaultParams() const { return ParamSet(parameters()); }
    // A reduced stage of the studio's progressive resolution renders 1/factor of the image in each axis; a technique
    // whose fixed cost does not shrink with the image may reduce that work too, in `params` (the view's): returns
    // what it reduced, a short phrase for the image's label ("coarser shadow maps"), or empty. The default reduces
    // nothing.
    virtual std::string reduceForPreview(ParamSet& params, int factor) const {
        (void)params;
        (void)factor;
        return {};
    }

    // Per scene element: can this technique render it?
    virtual Support supports(const HomogeneousMedium& medium) const = 0;
    virtual Support supports(const ParticleMedium& medium) const = 0;
    virtual Support supports(const PointLight& light) const = 0;
    virtual Support supports(const DirectionalLight& light) const = 0;
    virtual Support supports(const AreaLight& light) const = 0;
    virtual Support supports(const Material& material) const = 0;

    // Everything the technique cannot render in `scene`, one line each; empty when it can render all of it.
    std::vector<std::string> unsupported(const Scene& scene) const;
    // The lights and media of `scene` that this technique supports: a view's default part.
    ScenePart defaultPart(const Scene& scene) const;
    // The lights and media of `scene` that the default part leaves out, one line each with the reason.
    std::vector<std::string> leftOut(const Scene& scene) const;

    // Renders progressively until request.spp or request.timeLimit; throws Cancelled when cancelled, InputError when
    // the scene holds something unsupported (never a black image).
    virtual RenderResult render(const RenderRequest& request, const RenderCallbacks& callbacks) = 0;
    // Every check render() makes before it starts, without rendering: the technique prepares the scene as render()
    // would (OBJ files read, media clipped, its own limits) and throws InputError for what it would refuse. `tyndall
    // validate` calls it for every job. The default checks support only.
    virtual void check(const RenderRequest& request) const;

    virtual std::vector<ProbeInfo> probes() const { return {}; }
    virtual ProbeResult probe(const RenderRequest& request, const std::string& probeName, int x, int y);

protected:
    // Throws InputError naming the first element of `scene` this technique cannot render.
    void requireSupported(const Scene& scene) const;
    // The metadata every render carries: technique, parameters (JSON), spp, renderTime, seed.
    void stampMetadata(RenderResult& result, const RenderRequest& request) const;
};

// A progressive render's progress in [0, 1]: the larger of its share of targetSpp and of timeLimit (0: none).
double progressFraction(double doneSpp, int targetSpp, double elapsedSeconds, double timeLimit);

}  // namespace tyndall
