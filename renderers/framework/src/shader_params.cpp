#include "tyndall/framework/shader_params.h"

#include "tyndall/core/error.h"
#include "tyndall/core/phase_eval.h"

#include <cmath>

namespace tyndall {

namespace {
glm::vec3 toVec3(const glm::dvec3& v) {
    return glm::vec3(v);
}
}  // namespace

shader::CameraParams toCameraParams(const Camera& cam) {
    const Vec3 forward = glm::normalize(cam.target - cam.position);
    const Vec3 right = glm::normalize(glm::cross(forward, cam.up));
    const Vec3 up = glm::cross(right, forward);
    shader::CameraParams c{};
    c.position = toVec3(cam.position);
    c.forward = toVec3(forward);
    c.right = toVec3(right);
    c.up = toVec3(up);
    c.tanHalfFovY = float(std::tan(glm::radians(cam.fovY) * 0.5));
    c.aspect = float(cam.width) / float(cam.height);
    c.width = float(cam.width);
    c.height = float(cam.height);
    return c;
}

shader::MaterialParams toMaterialParams(const Material& m) {
    shader::MaterialParams mp{};
    mp.kind = m.kind == Material::Kind::Diffuse ? shader::kMaterialDiffuse : shader::kMaterialGgx;
    mp.albedo = toVec3(m.albedo);
    mp.f0 = toVec3(m.f0);
    mp.alphaX = float(m.alphaX);
    mp.alphaY = float(m.alphaY);
    return mp;
}

shader::PhaseParams toPhaseParams(const PhaseFunction& phase) {
    shader::PhaseParams p{};
    p.g = float(phase.g);
    p.a = float(phase.a);
    p.b = float(phase.b);
    switch (phase.kind) {
        case PhaseKind::Isotropic:
            p.kind = shader::kPhaseIsotropic;
            break;
        case PhaseKind::HenyeyGreenstein:
            p.kind = shader::kPhaseHenyeyGreenstein;
            break;
        case PhaseKind::IsoHgMix:
            p.kind = shader::kPhaseIsoHgMix;
            break;
        case PhaseKind::Rayleigh:
            p.kind = shader::kPhaseRayleigh;
            break;
        case PhaseKind::Eddington:
            p.kind = shader::kPhaseEddington;
            break;
        case PhaseKind::HazyMie:
            p.kind = shader::kPhaseHazyMie;
            break;
        case PhaseKind::MurkyMie:
            p.kind = shader::kPhaseMurkyMie;
            break;
        case PhaseKind::Legendre:
            p.kind = shader::kPhaseLegendre;
            TY_CHECK(phase.legendre.size() <= size_t(shader::kMaxLegendreTerms), "too many Legendre terms");
            p.terms = int(phase.legendre.size());
            for (size_t i = 0; i < phase.legendre.size(); ++i)
                p.legendre[i] = float(phase.legendre[i]);
            break;
    }
    return p;
}

double phaseValue(const PhaseFunction& phase, double mu) {
    return double(shader::phaseEval(toPhaseParams(phase), float(mu)));
}

}  // namespace tyndall
