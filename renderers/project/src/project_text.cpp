// updateProjectText: a project saved as an edit of the file it was loaded from. Where a value did not change, the file
// keeps the user's text (key order, number spelling, omitted defaults, layout), so that a one-value edit in the studio
// is a one-line diff for a project under version control. docs/project-format.md, "Saved files", says what users see.
//
// The project as loaded (`before`) and as edited (`after`) are compared as projectToJson, path by path, alongside the
// text: equal values keep their text span, changed ones are written over theirs, added keys and elements are inserted
// in the layout of their neighbours and removed ones are cut with their separators. Whatever the text does not map
// onto falls back to the whole object (or, at worst, to projectText), and the result must load as `after`.
#include "project_internal.h"

#include <algorithm>
#include <map>
#include <set>
#include <stdexcept>
#include <string_view>

namespace tyndall {

namespace {

using nlohmann::json;

constexpr std::size_t kNone = std::string::npos;

// The text cannot be mapped onto the project: saving writes the whole project instead.
struct Unmappable : std::runtime_error {
    Unmappable() : std::runtime_error("the project text cannot be mapped") {}
};

// ---------------------------------------------------------------------------------------------------------------------
// Where each value of a JSON text is. nlohmann's parser (and its SAX interface) reports no positions, so this scanner
// records them. It reads only text that nlohmann has parsed already (loading the project checks that first), so it
// skips rather than checks: a string ends at its first unescaped quote, a number or a literal at the next delimiter.

struct TextValue {
    std::size_t start = 0;  // where the item starts: an object member's key, or the value itself
    std::size_t begin = 0;  // the value is [begin, end)
    std::size_t end = 0;
    std::string key;               // an object member's key, decoded
    char kind = 0;                 // '{', '[', or 0 for a string, number or literal
    std::vector<TextValue> items;  // the members or elements, in the text's order
};

class Scanner {
public:
    explicit Scanner(const std::string& text) : text_(text) {}

    TextValue document() {
        if (text_.starts_with("\xEF\xBB\xBF")) pos_ = 3;  // nlohmann skips a UTF-8 byte order mark
        skipSpace();
        return value(pos_);
    }

private:
    char peek() const {
        if (pos_ >= text_.size()) throw Unmappable();
        return text_[pos_];
    }

    void skipSpace() {
        while (pos_ < text_.size() && std::string_view(" \t\r\n").find(text_[pos_]) != std::string_view::npos)
            ++pos_;
    }

    void skipString() {
        ++pos_;  // the opening quote
        while (peek() != '"')
            pos_ += text_[pos_] == '\\' ? 2 : 1;
        ++pos_;
    }

    TextValue value(std::size_t start) {
        TextValue v{.start = start, .begin = pos_};
        const char first = peek();
        if (first == '{' || first == '[') {
            v.kind = first;
            const char close = first == '{' ? '}' : ']';
            ++pos_;
            skipSpace();
            while (peek() != close) {
                const std::size_t itemStart = pos_;
                std::string key;
                if (first == '{') {
                    skipString();
                    key = json::parse(text_.substr(itemStart, pos_ - itemStart)).get<std::string>();  // escapes
                    skipSpace();
                    if (peek() != ':') throw Unmappable();
                    ++pos_;
                    skipSpace();
                }
                v.items.push_back(value(itemStart));
                v.items.back().key = std::move(key);
                skipSpace();
                if (peek() == ',') {
                    ++pos_;
                    skipSpace();
                }
            }
            ++pos_;
        } else if (first == '"') {
            skipString();
        } else {
            while (pos_ < text_.size() && std::string_view(",]} \t\r\n").find(text_[pos_]) == std::string_view::npos)
                ++pos_;
        }
        v.end = pos_;
        return v;
    }

    const std::string& text_;
    std::size_t pos_ = 0;
};

// ---------------------------------------------------------------------------------------------------------------------
// The edit of the text, value by value.

// A member or element of the new text: `index` is the text item it stands in place of, kNone for a new one.
struct Piece {
    std::size_t index = kNone;
    std::string text;
};

class Updater {
public:
    // `rewrite` holds JSON pointers (into `after`) of values to write whole even where their text maps.
    Updater(const std::string& text, const std::set<std::string>& rewrite) : text_(text), rewrite_(rewrite) {
        // The file's own indentation step (that of its second line) and line ends, for what is written new.
        const std::size_t secondLine = text.find('\n') + 1;
        const std::size_t indented = secondLine == 0 ? kNone : text.find_first_not_of(" \t", secondLine);
        if (indented != kNone && indented > secondLine) unit_ = text.substr(secondLine, indented - secondLine);
        if (text.find("\r\n") != kNone) newline_ = "\r\n";
    }

    // The text that replaces `node`'s value, whose text loads as `b`, so that it loads as `a`.
    std::string value(const TextValue& node, const json& b, const json& a, ObjectKind kind,
                      const json::json_pointer& at) const {
        const std::string pointer = at.to_string();
        if (rewrite_.count(pointer) > 0) return rewritten(node, a, kind);
        if (b == a && !holdsRewrite(pointer)) return span(node.begin, node.end);
        if (!node.items.empty()) {
            if (node.kind == '{' && b.is_object() && a.is_object()) return object(node, b, a, kind, at);
            if (node.kind == '[' && b.is_array() && a.is_array()) return array(node, b, a, kind, at);
        }
        return rewritten(node, a, kind);
    }

private:
    // Whether a value to write whole is inside the one at `pointer`.
    bool holdsRewrite(const std::string& pointer) const {
        const auto inside = rewrite_.lower_bound(pointer + "/");
        return inside != rewrite_.end() && inside->starts_with(pointer + "/");
    }

    std::string span(std::size_t begin, std::size_t end) const { return text_.substr(begin, end - begin); }

    bool isOneLine(const TextValue& node) const { return text_.find('\n', node.begin) >= node.end; }

    // The spaces and tabs that start the line holding `pos`.
    std::string lineIndent(std::size_t pos) const {
        const std::size_t newline = pos == 0 ? kNone : text_.rfind('\n', pos - 1);
        const std::size_t lineStart = newline == kNone ? 0 : newline + 1;
        const std::size_t indentEnd = text_.find_first_not_of(" \t", lineStart);
        return span(lineStart, std::min(indentEnd == kNone ? text_.size() : indentEnd, pos));
    }

    TextLayout layout(bool oneLine, std::string indent) const {
        return TextLayout{.oneLine = oneLine, .indent = std::move(indent), .unit = unit_, .newline = newline_};
    }

    // Whether nothing but the item (and a comma after it) stands on its line.
    bool isAloneOnItsLine(const TextValue& node) const {
        const std::size_t before = node.start == 0 ? kNone : text_.find_last_not_of(" \t", node.start - 1);
        const std::size_t after = text_.find_first_not_of(" \t,\r", node.end);
        return (before == kNone || text_[before] == '\n') && (after == kNone || text_[after] == '\n');
    }

    // `a` written over `node`'s value: on one line where the value was, else one member per line at its indentation.
    // An empty object or array has no layout to keep: alone on its line, it takes the one of saved files.
    std::string rewritten(const TextValue& node, const json& a, ObjectKind kind) const {
        const bool emptyAlone = node.kind != 0 && node.items.empty() && isAloneOnItsLine(node);
        return projectValueText(a, kind, layout(isOneLine(node) && !emptyAlone, lineIndent(node.begin)));
    }

    // The separator the container uses between items: its last one (",\n    " or ", ").
    std::string typicalSeparator(const TextValue& node) const {
        const std::vector<TextValue>& items = node.items;
        if (items.size() >= 2) return span(items[items.size() - 2].end, items.back().start);
        const std::string opening = span(node.begin + 1, items.front().start);
        return opening.find('\n') == kNone ? ", " : "," + opening;
    }

    // How a new item beside `neighbour` is written: on one line where the items are, or where the neighbour is.
    TextLayout newItemLayout(const TextValue& node, const TextValue& neighbour) const {
        const std::string separator = typicalSeparator(node);
        const std::size_t lastBreak = separator.rfind('\n');
        if (lastBreak == kNone) return layout(true, lineIndent(node.begin));
        return layout(isOneLine(neighbour), separator.substr(lastBreak + 1));
    }

    // The container with its items replaced by `pieces`, in order: the text's own opening, closing and separators
    // where they stand between items the text has, its typical separator around new ones.
    std::string join(const TextValue& node, const std::vector<Piece>& pieces) const {
        if (pieces.empty()) return node.kind == '{' ? "{}" : "[]";
        const std::vector<TextValue>& items = node.items;
        std::string out = span(node.begin, items.front().start);
        for (std::size_t k = 0; k < pieces.size(); ++k) {
            if (k > 0) {
                const std::size_t index = pieces[k].index;
                const bool bothFromText = index != kNone && index > 0 && pieces[k - 1].index != kNone;
                // After a deleted item this is the separator before it: its line goes, the line before stays.
                out += bothFromText ? span(items[index - 1].end, items[index].start) : typicalSeparator(node);
            }
            out += pieces[k].text;
        }
        return out + span(items.back().end, node.end);
    }

    std::string object(const TextValue& node, const json& b, const json& a, ObjectKind kind,
                       const json::json_pointer& at) const {
        std::set<std::string> written;
        bool spelledOtherwise = false;
        for (const TextValue& item : node.items) {
            written.insert(item.key);
            spelledOtherwise = spelledOtherwise || !b.contains(item.key);
        }
        std::vector<std::string> changed;  // keys whose value differs, or that only one of b and a holds
        for (const auto& item : a.items())
            if (!b.contains(item.key()) || b[item.key()] != item.value()) changed.push_back(item.key());
        for (const auto& item : b.items())
            if (!a.contains(item.key())) changed.push_back(item.key());
        // A key of the text that b lacks spells a field another way (albedo and extinction for sigma_s and sigma_a;
        // alphaX and alphaY for alpha) or does not apply to the type (g of an isotropic phase function). It is kept
        // while the fields it may stand for are unchanged. Otherwise the object is spelled as a has it: such keys go
        // (or take a's value where a has them) and every key of a that the text leaves out is written.
        const auto unwritten = [&](const std::string& key) { return !written.count(key); };
        const auto spelledOtherwiseInA = [&](const TextValue& item) {
            return !b.contains(item.key) && a.contains(item.key);
        };
        const bool respell =
            spelledOtherwise && (std::any_of(changed.begin(), changed.end(), unwritten) ||
                                 std::any_of(node.items.begin(), node.items.end(), spelledOtherwiseInA));
        const auto keys = keysInSchemaOrder(a, kind);
        const auto kindOf = [&](const std::string& key) {
            for (const auto& [name, child] : keys)
                if (name == key) return child;
            return ObjectKind::None;
        };
        std::vector<Piece> pieces;
        for (std::size_t i = 0; i < node.items.size(); ++i) {
            const TextValue& item = node.items[i];
            if (!b.contains(item.key)) {
                if (!respell) {
                    pieces.push_back({i, span(item.start, item.end)});
                } else if (a.contains(item.key)) {
                    pieces.push_back(
                        {i, span(item.start, item.begin) + rewritten(item, a[item.key], kindOf(item.key))});
                }
            } else if (a.contains(item.key)) {
                const std::string edited = value(item, b[item.key], a[item.key], kindOf(item.key), at / item.key);
                pieces.push_back({i, span(item.start, item.begin) + edited});
            }  // else removed
        }
        // What a adds or changes and the text leaves out (a default it omitted) goes at the end, in the schema's order.
        // A key that only b holds and the text leaves out was a default that no longer applies: nothing to remove.
        const TextLayout newLayout = newItemLayout(node, node.items.back());
        for (const auto& [key, child] : keys) {
            if (written.count(key) || (!respell && b.contains(key) && b[key] == a[key])) continue;
            pieces.push_back({kNone, json(key).dump() + ": " + projectValueText(a[key], child, newLayout)});
        }
        return join(node, pieces);
    }

    // The name of a named element (lights, media, materials, meshes, views), or null.
    static const std::string* nameOf(const json& element) {
        if (!element.is_object()) return nullptr;
        const auto name = element.find("name");
        return name != element.end() && name->is_string() ? &name->get_ref<const std::string&>() : nullptr;
    }

    std::string array(const TextValue& node, const json& b, const json& a, ObjectKind kind,
                      const json::json_pointer& at) const {
        const std::vector<TextValue>& items = node.items;
        if (b.size() != items.size()) return rewritten(node, a, kind);
        // textOfB[j]: the text element that loads as b[j]; bOfA[i]: the element of b that a[i] is an edit of.
        std::vector<std::size_t> textOfB(b.size()), bOfA(a.size(), kNone);
        const auto named = [](const json& array) {
            return std::all_of(array.begin(), array.end(), [](const json& e) { return nameOf(e) != nullptr; });
        };
        if (named(b) && named(a)) {
            // Paired by name: lights are loaded grouped by type, so b's order need not be the text's.
            std::map<std::string, std::size_t> textByName, bByName;
            for (std::size_t t = 0; t < items.size(); ++t) {
                const auto name = std::find_if(items[t].items.begin(), items[t].items.end(),
                                               [](const TextValue& member) { return member.key == "name"; });
                if (items[t].kind != '{' || name == items[t].items.end()) throw Unmappable();
                const json decoded = json::parse(span(name->begin, name->end));
                if (!decoded.is_string() || !textByName.emplace(decoded.get<std::string>(), t).second)
                    throw Unmappable();
            }
            for (std::size_t j = 0; j < b.size(); ++j) {
                const auto text = textByName.find(*nameOf(b[j]));
                if (text == textByName.end()) throw Unmappable();
                textOfB[j] = text->second;
                bByName.emplace(*nameOf(b[j]), j);
            }
            std::vector<bool> paired(b.size(), false);
            for (std::size_t i = 0; i < a.size(); ++i) {
                const auto found = bByName.find(*nameOf(a[i]));
                if (found != bByName.end()) paired[found->second] = true, bOfA[i] = found->second;
            }
            // A new name where b's element at the same place has gone is a rename (or a replacement): edit it there.
            for (std::size_t i = 0; i < a.size() && i < b.size(); ++i)
                if (bOfA[i] == kNone && !paired[i]) paired[i] = true, bOfA[i] = i;
        } else {
            for (std::size_t j = 0; j < b.size(); ++j)
                textOfB[j] = j;
            for (std::size_t i = 0; i < a.size() && i < b.size(); ++i)
                bOfA[i] = i;
        }
        // Kept elements stay where the text has them: a that reorders them is written whole.
        std::size_t lastPaired = 0;
        for (std::size_t i = 0; i < a.size(); ++i) {
            if (bOfA[i] == kNone) continue;
            if (bOfA[i] + 1 <= lastPaired) return rewritten(node, a, kind);
            lastPaired = bOfA[i] + 1;
        }
        // aOfText[t]: the element of a that text element t becomes (kNone: removed). New elements of a go after the
        // text element of the paired element before them in a (newAfter[t + 1]), or before every element (newAfter[0]).
        std::vector<std::size_t> aOfText(items.size(), kNone);
        std::vector<std::vector<std::size_t>> newAfter(items.size() + 1);
        std::size_t slot = 0;
        for (std::size_t i = 0; i < a.size(); ++i) {
            if (bOfA[i] == kNone) {
                newAfter[slot].push_back(i);
            } else {
                aOfText[textOfB[bOfA[i]]] = i;
                slot = textOfB[bOfA[i]] + 1;
            }
        }
        std::vector<Piece> pieces;
        const auto addNew = [&](std::size_t s) {
            const TextLayout newLayout = newItemLayout(node, items[s == 0 ? 0 : s - 1]);
            for (std::size_t i : newAfter[s])
                pieces.push_back({kNone, projectValueText(a[i], kind, newLayout)});
        };
        addNew(0);
        for (std::size_t t = 0; t < items.size(); ++t) {
            const std::size_t i = aOfText[t];
            if (i != kNone) {
                const std::size_t j = bOfA[i];
                pieces.push_back({t, value(items[t], b[j], a[i], kind, at / i)});
            }
            addNew(t + 1);
        }
        return join(node, pieces);
    }

    const std::string& text_;
    const std::set<std::string>& rewrite_;
    std::string unit_ = "  ";
    std::string newline_ = "\n";
};

// How many times a text that does not load as the edited project is mended before the whole project is written.
constexpr int kMendings = 8;

}  // namespace

std::string updateProjectText(const TechniqueCatalogue& techniques, const ProjectFile& original,
                              const Project& edited) {
    if (original.text.empty()) return projectText(edited);
    const json after = projectToJson(edited);
    try {
        const json before = projectToJson(original.project);
        // The text must load as the project compared against: it does not when --set overrides were applied.
        if (projectToJson(parseProject(techniques, original.text, original.path)) != before) return projectText(edited);
        if (before == after) return original.text;
        const TextValue root = Scanner(original.text).document();
        std::set<std::string> rewrite;
        for (int attempt = 0; attempt <= kMendings; ++attempt) {
            const Updater updater(original.text, rewrite);
            const std::string text = original.text.substr(0, root.begin) +
                                     updater.value(root, before, after, ObjectKind::Project, json::json_pointer()) +
                                     original.text.substr(root.end);
            // Correct output comes first: what is saved must load as the edited project, whatever the text held.
            const json loaded = projectToJson(parseProject(techniques, text, original.path));
            if (loaded == after) return text;
            // A value kept as written can mean something else beside a changed one (a plane's offset is divided by
            // its normal's length, which changed): write the first difference as `after` has it, and try again; when
            // that was tried already, the value around it.
            json::json_pointer around(json::diff(loaded, after).at(0).at("path").get<std::string>());
            while (!around.empty() && rewrite.count(around.to_string()) > 0)
                around = around.parent_pointer();
            if (around.empty()) break;  // only the whole project is left to write
            rewrite.insert(around.to_string());
        }
    } catch (const std::exception&) {
        // Unmappable, or a text that does not load (an edit that the text's spelling of a field conflicts with).
    }
    return projectText(edited);
}

}  // namespace tyndall
