// The Pegoraro technique: exact single scattering from point lights in infinite homogeneous media, in closed form
// (Pegoraro, Schott, Parker, EGSR 2010; ../shared/papers/003), with exact volumetric shadows from lit intervals.
// Renders on the GPU (Vulkan compute) or the CPU from the same shared code (shaders/shared/pegoraro*.h).
#pragma once

#include "tyndall/framework/technique.h"

#include <memory>

namespace tyndall {

class PegoraroTechnique final : public Technique {
public:
    PegoraroTechnique();
    ~PegoraroTechnique() override;

    std::string name() const override { return "pegoraro"; }
    std::string displayName() const override { return "Pegoraro closed form"; }
    std::vector<ParamInfo> parameters() const override;

    Support supports(const HomogeneousMedium& medium) const override;
    Support supports(const ParticleMedium&) const override;
    Support supports(const PointLight& light) const override;
    Support supports(const DirectionalLight&) const override;
    Support supports(const AreaLight&) const override;
    Support supports(const Material&) const override { return Support::yes(); }

    RenderResult render(const RenderRequest& request, const RenderCallbacks& callbacks) override;
    void check(const RenderRequest& request) const override;

    // The most polynomial terms a light distribution may have (a spot exponent of at most 32).
    static constexpr int kMaxLightTerms = 33;

private:
};

}  // namespace tyndall
