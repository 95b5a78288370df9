// What the project library knows of techniques: the names a view may give, their parameters and the part of a scene
// each renders by default. The project library knows no technique itself; the technique registry hands it the
// built-in ones (techniqueCatalogue() in tyndall/techniques/registry.h), and a test may hand its own.
#pragma once

#include "tyndall/core/params.h"
#include "tyndall/core/scene.h"

#include <optional>
#include <string>
#include <vector>

namespace tyndall {

class TechniqueCatalogue {
public:
    virtual ~TechniqueCatalogue() = default;

    // Every technique's name, sorted.
    virtual std::vector<std::string> names() const = 0;
    // The parameters of `technique`, or nullopt when no technique has that name.
    virtual std::optional<std::vector<ParamInfo>> parameters(const std::string& technique) const = 0;
    // The lights and media of `scene` that `technique` renders when a view names no part of its own. `technique` must
    // be one of names().
    virtual ScenePart defaultPart(const std::string& technique, const Scene& scene) const = 0;
};

}  // namespace tyndall
