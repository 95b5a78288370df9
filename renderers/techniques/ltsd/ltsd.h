// The LTSD technique: noise-free unshadowed single scattering from polygonal area lights in a homogeneous medium (KT,
// Shah and Narayanan, "Linearly Transformed Spherical Distributions for Interactive Single Scattering with Area
// Lights", Eurographics 2025; ../shared/papers/000): the aggregated transmittance (Eq. 10, or a better polygon
// average), the analytic in-scattered radiance through the phase function's fitted LTSDs (Eq. 14, 21, tables/), the
// air-light as an N-node quadrature (Eq. 15) and the analytic radiance of diffuse surfaces (Eq. 12). Renders on the
// GPU (Vulkan compute) or the CPU from the same shared code (shaders/shared/ltsd_scene.h). docs/ltsd.md.
#pragma once

#include "tyndall/framework/technique.h"

#include <memory>

namespace tyndall {

class LtsdTechnique final : public Technique {
public:
    LtsdTechnique();
    ~LtsdTechnique() override;

    std::string name() const override { return "ltsd"; }
    std::string displayName() const override { return "LTSD"; }
    std::string labelFor(const ParamSet& params) const override;
    std::vector<ParamInfo> parameters() const override;
    // Its cost per pixel is its nodes and ratio samples: a preview has fewer (and no supersampling).
    std::string reduceForPreview(ParamSet& params, int factor) const override;

    Support supports(const HomogeneousMedium& medium) const override;
    Support supports(const ParticleMedium& medium) const override;
    Support supports(const PointLight& light) const override;
    Support supports(const DirectionalLight& light) const override;
    Support supports(const AreaLight& light) const override;
    Support supports(const Material& material) const override;

    RenderResult render(const RenderRequest& request, const RenderCallbacks& callbacks) override;
    void check(const RenderRequest& request) const override;

private:
};

}  // namespace tyndall
