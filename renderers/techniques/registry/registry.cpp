// The registry of techniques by name. Built-in techniques are listed here explicitly.
#include "tyndall/techniques/registry.h"

#include "tyndall/core/error.h"
#include "tyndall/core/text.h"

#include "isv/isv.h"
#include "ltsd/ltsd.h"
#include "pegoraro/pegoraro.h"
#include "volume_ris/volume_ris.h"
#include "wvds/wvds.h"
#include "reference/reference.h"

#include <map>
#include <mutex>

namespace tyndall {

namespace {
struct Registry {
    std::mutex mutex;
    std::map<std::string, TechniqueFactory> factories;

    Registry() {
        factories["reference"] = [] { return std::make_unique<ReferenceTechnique>(); };
        factories["pegoraro"] = [] { return std::make_unique<PegoraroTechnique>(); };
        factories["ltsd"] = [] { return std::make_unique<LtsdTechnique>(); };
        factories["wvds"] = [] { return std::make_unique<WvdsTechnique>(); };
        factories["volume-ris"] = [] { return std::make_unique<VolumeRisTechnique>(); };
        factories["isv"] = [] { return std::make_unique<IsvTechnique>(); };
    }
};

Registry& registry() {
    static Registry instance;
    return instance;
}
}  // namespace

std::vector<std::string> techniqueNames() {
    Registry& r = registry();
    std::lock_guard lock(r.mutex);
    std::vector<std::string> names;
    for (const auto& [name, factory] : r.factories) names.push_back(name);
    return names;
}

bool hasTechnique(const std::string& name) {
    Registry& r = registry();
    std::lock_guard lock(r.mutex);
    return r.factories.count(name) != 0;
}

std::unique_ptr<Technique> createTechnique(const std::string& name) {
    TechniqueFactory factory;
    {
        Registry& r = registry();
        std::lock_guard lock(r.mutex);
        auto it = r.factories.find(name);
        if (it != r.factories.end()) factory = it->second;
    }
    if (!factory) {
        std::string message = "unknown technique '" + name + "'";
        std::vector<std::string> names = techniqueNames();
        std::string nearest = nearestName(name, names);
        if (!nearest.empty()) message += "; did you mean '" + nearest + "'?";
        message += " Known techniques:";
        for (const std::string& n : names) message += " " + n;
        throw InputError(InputLocation{"", 0, 0, "technique"}, message);
    }
    return factory();
}

namespace {
class RegistryCatalogue final : public TechniqueCatalogue {
public:
    std::vector<std::string> names() const override { return techniqueNames(); }
    std::optional<std::vector<ParamInfo>> parameters(const std::string& technique) const override {
        if (!hasTechnique(technique)) return std::nullopt;
        return createTechnique(technique)->parameters();
    }
    ScenePart defaultPart(const std::string& technique, const Scene& scene) const override {
        return createTechnique(technique)->defaultPart(scene);
    }
};
}  // namespace

const TechniqueCatalogue& techniqueCatalogue() {
    static const RegistryCatalogue catalogue;
    return catalogue;
}

void registerTechnique(const std::string& name, TechniqueFactory factory) {
    TY_CHECK(static_cast<bool>(factory), "a technique factory must be callable");
    Registry& r = registry();
    std::lock_guard lock(r.mutex);
    r.factories[name] = std::move(factory);
}

}  // namespace tyndall
