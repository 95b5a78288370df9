// The WVDS box technique: collimated single scattering in a bounded convex homogeneous medium (Velinov and Mitchell,
// "Collimated Whole Volume Light Scattering in Homogeneous Finite Media"; ../shared/papers/001). The analytic
// unoccluded integral over the light-view section, whole-volume distance sampling, and the estimators the paper
// compares (MCWVDS, REDS, REES, RM, MCDS), with visibility by shadow rays through the GPU framework's BVH. Renders on
// the GPU (Vulkan compute) or the CPU from the same shared code (shaders/shared/wvds*.h).
#pragma once

#include "tyndall/framework/technique.h"

#include <memory>

namespace tyndall {

class WvdsTechnique final : public Technique {
public:
    WvdsTechnique();
    ~WvdsTechnique() override;

    std::string name() const override { return "wvds"; }
    std::string displayName() const override { return "WVDS box"; }
    std::vector<ParamInfo> parameters() const override;

    Support supports(const HomogeneousMedium& medium) const override;
    Support supports(const ParticleMedium& medium) const override;
    Support supports(const PointLight& light) const override;
    Support supports(const DirectionalLight& light) const override;
    Support supports(const AreaLight& light) const override;
    Support supports(const Material&) const override { return Support::yes(); }

    RenderResult render(const RenderRequest& request, const RenderCallbacks& callbacks) override;
    void check(const RenderRequest& request) const override;

    // "distances": at a pixel, histograms (256 bins) of the distances each strategy samples along the centre ray, with
    // their analytic pdfs (the paper's Fig. 4 and 5). "convergence": relMSE of every estimator against a converged
    // image over spp 1, 2, 4, ... (Fig. 7); x and y are ignored.
    std::vector<ProbeInfo> probes() const override;
    ProbeResult probe(const RenderRequest& request, const std::string& probeName, int x, int y) override;

private:
};

}  // namespace tyndall
