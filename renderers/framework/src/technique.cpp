#include "tyndall/framework/technique.h"

#include "tyndall/core/error.h"

#include <nlohmann/json.hpp>

#include <algorithm>

namespace tyndall {

namespace {
template <typename Element>
void collectUnsupported(const Technique& technique, const std::vector<Element>& elements, const char* what,
                        std::vector<std::string>& out) {
    for (const Element& element : elements) {
        Support s = technique.supports(element);
        if (!s.supported) out.push_back(std::string(what) + " '" + element.name + "': " + s.reason);
    }
}

template <typename Element>
void collectSupportedNames(const Technique& technique, const std::vector<Element>& elements,
                           std::vector<std::string>& out) {
    for (const Element& element : elements)
        if (technique.supports(element).supported) out.push_back(element.name);
}
}  // namespace

std::vector<std::string> Technique::unsupported(const Scene& scene) const {
    std::vector<std::string> out = leftOut(scene);
    collectUnsupported(*this, scene.materials, "material", out);
    return out;
}

void Technique::check(const RenderRequest& request) const {
    requireSupported(request.scene);
}

void Technique::requireSupported(const Scene& scene) const {
    const std::vector<std::string> missing = unsupported(scene);
    if (!missing.empty())
        throw InputError(InputLocation{"", 0, 0, "scene"},
                         "the technique '" + name() + "' cannot render " + missing[0]);
}

void Technique::stampMetadata(RenderResult& result, const RenderRequest& request) const {
    nlohmann::json params = nlohmann::json::object();
    for (const auto& [key, value] : request.params.values())
        params[key] = toString(value);
    auto& meta = result.image.metadata;
    meta["technique"] = name();
    meta["parameters"] = params.dump();
    meta["spp"] = std::to_string(result.spp);
    meta["renderTime"] = std::to_string(result.seconds);
    meta["seed"] = std::to_string(request.seed);
}

ScenePart Technique::defaultPart(const Scene& scene) const {
    ScenePart part;
    collectSupportedNames(*this, scene.pointLights, part.lights);
    collectSupportedNames(*this, scene.directionalLights, part.lights);
    collectSupportedNames(*this, scene.areaLights, part.lights);
    collectSupportedNames(*this, scene.media, part.media);
    collectSupportedNames(*this, scene.particleMedia, part.media);
    return part;
}

double progressFraction(double doneSpp, int targetSpp, double elapsedSeconds, double timeLimit) {
    double fraction = targetSpp > 0 ? doneSpp / targetSpp : 0.0;
    if (timeLimit > 0.0) fraction = std::max(fraction, elapsedSeconds / timeLimit);
    return std::clamp(fraction, 0.0, 1.0);
}

std::vector<std::string> Technique::leftOut(const Scene& scene) const {
    std::vector<std::string> out;
    collectUnsupported(*this, scene.media, "medium", out);
    collectUnsupported(*this, scene.particleMedia, "particle medium", out);
    collectUnsupported(*this, scene.pointLights, "point light", out);
    collectUnsupported(*this, scene.directionalLights, "directional light", out);
    collectUnsupported(*this, scene.areaLights, "area light", out);
    return out;
}

ProbeResult Technique::probe(const RenderRequest&, const std::string& probeName, int, int) {
    std::string known;
    for (const ProbeInfo& p : probes())
        known += (known.empty() ? "" : ", ") + p.name;
    throw InputError(InputLocation{"", 0, 0, "probe"}, "technique '" + name() + "' has no probe '" + probeName + "'; " +
                                                           (known.empty() ? "it has none" : "it has " + known));
}

}  // namespace tyndall
