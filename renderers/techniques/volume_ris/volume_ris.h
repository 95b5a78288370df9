// Volume-RIS: single scattering from polygonal area lights in a homogeneous medium by resampled importance sampling
// of candidate (distance, light point) pairs along each camera ray, with one shadow ray for the chosen pair (Lin, Wyman
// and Yuksel 2021, without spatial or temporal reuse, as the LTSD paper (000) uses it for its baseline). Unbiased.
// Renders on the GPU (Vulkan compute) or the CPU from the same shared code (shaders/shared/volume_ris.h).
// docs/volume-ris.md.
#pragma once

#include "tyndall/framework/technique.h"

#include <memory>

namespace tyndall {

class VolumeRisTechnique final : public Technique {
public:
    VolumeRisTechnique();
    ~VolumeRisTechnique() override;

    std::string name() const override { return "volume-ris"; }
    std::string displayName() const override { return "Volume-RIS"; }
    std::vector<ParamInfo> parameters() const override;

    Support supports(const HomogeneousMedium& medium) const override;
    Support supports(const ParticleMedium& medium) const override;
    Support supports(const PointLight& light) const override;
    Support supports(const DirectionalLight& light) const override;
    Support supports(const AreaLight& light) const override;
    Support supports(const Material&) const override { return Support::yes(); }

    RenderResult render(const RenderRequest& request, const RenderCallbacks& callbacks) override;
    void check(const RenderRequest& request) const override;

private:
};

}  // namespace tyndall
