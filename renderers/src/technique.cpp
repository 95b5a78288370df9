#include "tyndall/technique.h"

#include "tyndall/error.h"

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
    std::vector<std::string> out;
    collectUnsupported(*this, scene.media, "medium", out);
    collectUnsupported(*this, scene.particleMedia, "particle medium", out);
    collectUnsupported(*this, scene.pointLights, "point light", out);
    collectUnsupported(*this, scene.directionalLights, "directional light", out);
    collectUnsupported(*this, scene.areaLights, "area light", out);
    collectUnsupported(*this, scene.materials, "material", out);
    return out;
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

ProbeResult Technique::probe(const RenderRequest&, const std::string& probeName, int, int) {
    throw InputError(InputLocation{"", 0, 0, "probe"},
                     "technique '" + name() + "' has no probe '" + probeName + "'; it has none");
}

}  // namespace tyndall
