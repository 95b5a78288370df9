// The ISV technique: volumetric particle systems rendered with interval shading (Jandhyala 2025, "Volumetric
// Rendering of Particle Systems using Interval Shading", ../shared/papers/004). Each particle is a tetrahedron of
// Gaussian-faded extinction, drawn back to front as projected-tetrahedron proxies whose fragments receive the ray's
// depth interval through it (Tricard 2024), shaded by one of the thesis' integration modes with a volumetric shadow map
// for self-shadowing and an opaque shadow map, and composited with premultiplied blending. Renders with Vulkan graphics
// pipelines or on the CPU (the same passes per pixel centre) from one shared source (shaders/shared/isv.h).
// docs/isv.md.
#pragma once

#include "tyndall/framework/technique.h"

#include <memory>

namespace tyndall {

class IsvTechnique final : public Technique {
public:
    IsvTechnique();
    ~IsvTechnique() override;

    std::string name() const override { return "isv"; }
    std::string displayName() const override { return "ISV particles"; }
    std::vector<ParamInfo> parameters() const override;
    // Its shadow maps do not shrink with the image: a preview's are coarser (and it has no supersampling).
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
