// The techniques by name: the only place that knows every built-in technique. The CLI, the studio and render jobs
// create techniques here; the project library sees them through techniqueCatalogue().
#pragma once

#include "tyndall/framework/technique.h"
#include "tyndall/project/catalogue.h"

#include <functional>
#include <memory>
#include <string>
#include <vector>

namespace tyndall {

// Built-in techniques are registered explicitly (static registration is dropped by linkers when the library is
// static).
using TechniqueFactory = std::function<std::unique_ptr<Technique>()>;

std::vector<std::string> techniqueNames();
bool hasTechnique(const std::string& name);
// Throws InputError with the nearest known name when `name` is unknown.
std::unique_ptr<Technique> createTechnique(const std::string& name);
void registerTechnique(const std::string& name, TechniqueFactory factory);

// The registered techniques as the project library sees them (names, parameters, default parts); it follows later
// registrations.
const TechniqueCatalogue& techniqueCatalogue();

}  // namespace tyndall
