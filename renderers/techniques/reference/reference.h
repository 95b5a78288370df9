// The reference: an unbiased Embree CPU path tracer that renders everything the scene model can describe, in single-
// or multiple-scattering mode (docs/conventions.md). Every technique is compared against it.
#pragma once

#include "tyndall/framework/technique.h"

namespace tyndall {

class ReferenceTechnique final : public Technique {
public:
    std::string name() const override { return "reference"; }
    std::string displayName() const override { return "Reference (path traced)"; }
    std::vector<ParamInfo> parameters() const override;

    Support supports(const HomogeneousMedium&) const override { return Support::yes(); }
    Support supports(const ParticleMedium&) const override { return Support::yes(); }
    Support supports(const PointLight&) const override { return Support::yes(); }
    Support supports(const DirectionalLight&) const override { return Support::yes(); }
    Support supports(const AreaLight&) const override { return Support::yes(); }
    Support supports(const Material&) const override { return Support::yes(); }

    RenderResult render(const RenderRequest& request, const RenderCallbacks& callbacks) override;
    void check(const RenderRequest& request) const override;

    static constexpr int kDefaultSpp = 64;
};

}  // namespace tyndall
