// --set overrides: "path=value" applied to a project's JSON before it is validated. A path is keys separated by dots,
// with [i] selecting an array element by index, [name] by its "name", and a final [+] appending the value as a new
// element (docs/project-format.md).
#include "project_internal.h"

#include <cctype>

namespace tyndall {

namespace {

using nlohmann::json;

struct PathStep {
    enum class Type { Key, Index, Name, Append };
    Type type = Type::Key;
    std::string key;  // Key: the key; Name: the element's name
    std::size_t index = 0;
};

[[noreturn]] void failOverride(const std::string& path, const std::string& message) {
    throw InputError(InputLocation{.field = "--set " + path}, message);
}

std::string trimmed(const std::string& s) {
    const auto first = s.find_first_not_of(" \t");
    if (first == std::string::npos) return "";
    return s.substr(first, s.find_last_not_of(" \t") - first + 1);
}

bool allDigits(const std::string& s) {
    return !s.empty() && std::all_of(s.begin(), s.end(), [](unsigned char c) { return std::isdigit(c); });
}

std::vector<PathStep> parsePath(const std::string& path) {
    std::vector<PathStep> steps;
    std::size_t i = 0;
    while (i < path.size()) {
        if (path[i] == '[') {
            const std::size_t close = path.find(']', i);
            if (close == std::string::npos) failOverride(path, "'[' without a matching ']'");
            const std::string inside = path.substr(i + 1, close - i - 1);
            if (inside.empty()) failOverride(path, "empty [] in the path; use [index], [name] or [+]");
            if (inside == "+") {
                if (close + 1 != path.size())
                    failOverride(path, "[+] appends the value as a whole new element, so it must end the path");
                steps.push_back({PathStep::Type::Append});
            } else if (allDigits(inside)) {
                // Leading zeros aside, more than nine digits exceed any array a project can hold.
                const std::string digits = inside.substr(std::min(inside.find_first_not_of('0'), inside.size() - 1));
                if (digits.size() > 9) failOverride(path, "index [" + clipForMessage(inside) + "] is too large");
                steps.push_back({PathStep::Type::Index, "", std::stoul(digits)});
            } else {
                steps.push_back({PathStep::Type::Name, inside});
            }
            i = close + 1;
            continue;
        }
        if (path[i] == '.') {
            if (steps.empty()) failOverride(path, "the path starts with '.'");
            ++i;
        } else if (!steps.empty()) {
            failOverride(path, "expected '.' or '[' after '" + path.substr(0, i) + "'");
        }
        const std::size_t end = path.find_first_of(".[", i);
        const std::string key = path.substr(i, end == std::string::npos ? std::string::npos : end - i);
        if (key.empty()) failOverride(path, "empty key in the path");
        steps.push_back({PathStep::Type::Key, key});
        i = end == std::string::npos ? path.size() : end;
    }
    if (steps.empty() || steps.front().type != PathStep::Type::Key)
        failOverride(path, "the path must start with a key");
    return steps;
}

// A value is JSON when it parses as JSON, otherwise the text itself: `name=fog` needs no quotes.
// Checked like a project file (nesting depth, duplicate keys, UTF-8), since the value becomes part of one.
json parseValue(const std::string& path, const std::string& text) {
    // accept() builds nothing, so a deeply nested value is refused before any tree exists.
    if (json::accept(text)) {
        checkJsonText(text, "", "--set " + path);
        return json::parse(text);
    }
    if (!isValidUtf8(text)) failOverride(path, "the value is not valid UTF-8");
    return json(text);
}

std::string describeLocation(const std::string& where) {
    return where.empty() ? "the project" : "'" + where + "'";
}

// "; did you mean 'x'?" or, when nothing is close, the list of what is allowed.
std::string suggestion(const std::string& key, const std::vector<std::string>& known) {
    const std::string nearest = nearestName(key, known);
    if (!nearest.empty()) return "; did you mean '" + nearest + "'?";
    std::string list;
    for (const std::string& name : known)
        list += (list.empty() ? "" : ", ") + name;
    return list.empty() ? "" : "; allowed: " + list;
}

// The technique parameters a view may set, or nullopt when its technique is unknown (validation reports that later).
std::optional<std::vector<std::string>> parameterNames(const TechniqueCatalogue& techniques, const json* view) {
    if (!view || !view->contains("technique") || !(*view)["technique"].is_string()) return std::nullopt;
    const auto parameters = techniques.parameters((*view)["technique"].get<std::string>());
    if (!parameters) return std::nullopt;
    std::vector<std::string> names;
    for (const ParamInfo& info : *parameters)
        names.push_back(info.name);
    return names;
}

// Walks the JSON tree along the path, following the project schema so that missing keys with defaults can be set.
class OverrideWalker {
public:
    OverrideWalker(const TechniqueCatalogue& techniques, json& root, std::string path)
        : techniques_(techniques), node_(&root), path_(std::move(path)) {}

    void apply(const std::vector<PathStep>& steps, const json& value) {
        for (std::size_t i = 0; i < steps.size(); ++i) {
            const bool last = i + 1 == steps.size();
            if (steps[i].type == PathStep::Type::Append) {
                if (!node_->is_array()) failOverride(path_, describeLocation(where_) + " is not an array");
                node_->push_back(value);
                return;
            }
            if (steps[i].type == PathStep::Type::Key) {
                const bool appends = !last && steps[i + 1].type == PathStep::Type::Append;
                if (!stepIntoKey(steps[i].key, last, appends, value)) return;
            } else {
                stepIntoElement(steps[i]);
            }
        }
        *node_ = value;
    }

private:
    KeySpec findKey(const std::string& key) const {
        if (kind_ == ObjectKind::Parameters) {
            const auto names = parameterNames(techniques_, view_);
            if (names && std::find(names->begin(), names->end(), key) == names->end()) {
                failOverride(
                    path_, "unknown parameter '" + clipForMessage(key) + "' in " + describeLocation(where_) + suggestion(key, *names));
            }
            return {""};
        }
        const ObjectKind kind = kind_ == ObjectKind::Light ? lightKind(*node_) : kind_;
        for (const KeySpec& spec : keySpecs(kind)) {
            if (key == spec.name) return spec;
        }
        failOverride(path_,
                     "unknown key '" + clipForMessage(key) + "' in " + describeLocation(where_) + suggestion(key, keyNames(kind)));
    }

    // Returns false when the key was missing and has been created with the value. `appends`: the next step is [+],
    // so a missing array is created empty.
    bool stepIntoKey(const std::string& key, bool last, bool appends, const json& value) {
        if (!node_->is_object()) failOverride(path_, describeLocation(where_) + " is not an object");
        const KeySpec spec = findKey(key);
        if (!node_->contains(key)) {
            if (last) {
                (*node_)[key] = value;
                return false;
            }
            if (appends && spec.array) {
                (*node_)[key] = json::array();
            } else if (spec.child == ObjectKind::None || spec.array) {
                failOverride(path_, "'" + key + "' is not in " + describeLocation(where_) + ", so it has no elements");
            } else {
                (*node_)[key] = json::object();
            }
        }
        if (kind_ == ObjectKind::View && key == "parameters") view_ = node_;
        node_ = &(*node_)[key];
        kind_ = spec.child;
        where_ = where_.empty() ? key : where_ + "." + key;
        return true;
    }

    void stepIntoElement(const PathStep& step) {
        if (!node_->is_array()) failOverride(path_, describeLocation(where_) + " is not an array");
        const std::size_t index = step.type == PathStep::Type::Index ? step.index : indexOfName(step.key);
        if (index >= node_->size()) {
            failOverride(path_, "index " + std::to_string(index) + " is out of range: " + describeLocation(where_) +
                                    " has " + std::to_string(node_->size()) + " elements");
        }
        node_ = &(*node_)[index];
        where_ += "[" + std::to_string(index) + "]";
    }

    std::size_t indexOfName(const std::string& name) const {
        std::vector<std::string> names;
        for (std::size_t i = 0; i < node_->size(); ++i) {
            const json& element = (*node_)[i];
            if (!element.is_object() || !element.contains("name") || !element["name"].is_string()) continue;
            if (element["name"] == name) return i;
            names.push_back(element["name"].get<std::string>());
        }
        failOverride(
            path_, "no element of " + describeLocation(where_) + " is named '" + clipForMessage(name) + "'" + suggestion(name, names));
    }

    const TechniqueCatalogue& techniques_;
    json* node_;
    ObjectKind kind_ = ObjectKind::Project;  // of the object at node_, or of the elements of the array at node_
    const json* view_ = nullptr;             // the view whose parameters are being set
    std::string where_;                      // the path walked so far, with indices
    std::string path_;                       // the whole path, as given
};

void applyOverride(const TechniqueCatalogue& techniques, json& root, const std::string& override) {
    const std::size_t equals = override.find('=');
    if (equals == std::string::npos) failOverride(override, "expected path=value, e.g. camera.fovY=50");
    const std::string path = trimmed(override.substr(0, equals));
    const std::vector<PathStep> steps = parsePath(path);
    OverrideWalker(techniques, root, path).apply(steps, parseValue(path, override.substr(equals + 1)));
}

}  // namespace

void applyOverrides(const TechniqueCatalogue& techniques, json& root, const std::vector<std::string>& overrides) {
    for (const std::string& override : overrides)
        applyOverride(techniques, root, override);
}

}  // namespace tyndall
