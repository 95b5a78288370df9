// `tyndall tables` and `tyndall tables eval`: the fitted LTSD tables' provenance and error summary, and a probe of the
// fit over any spherical polygon (docs/tables.md); `tyndall plot ltsd-polar|ltsd-error`: the studio's LTSD plots' data.
#include "commands.h"

#include "tyndall/core/error.h"
#include "tyndall/core/output.h"
#include "tyndall/tables/ltc_table.h"
#include "tyndall/tables/ltsd_table.h"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <tuple>

namespace tyndall::cli {

namespace {

nlohmann::json parseArgument(const std::string& text, const std::string& option) {
    try {
        return nlohmann::json::parse(text);
    } catch (const nlohmann::json::exception& e) {
        throw InputError(InputLocation{"", 0, 0, option}, std::string("not valid JSON: ") + e.what());
    }
}

LtsdPhase parsePhase(const std::string& text) {
    const nlohmann::json j = parseArgument(text, "--phase");
    if (!j.is_object() || !j.contains("type") || !j["type"].is_string())
        throw InputError(InputLocation{"", 0, 0, "--phase"}, "must be an object with a \"type\", e.g. {\"type\":\"hg\",\"g\":0.5}");
    LtsdPhase phase;
    phase.type = j["type"].get<std::string>();
    if (!ltsdPhaseRefusal(phase.type).empty())
        throw InputError(InputLocation{"", 0, 0, "--phase.type"},
                         "the LTSD technique cannot take '" + phase.type + "': " + ltsdPhaseRefusal(phase.type));
    // The keys each type takes (docs/project-format.md) and their ranges.
    std::vector<std::string> allowed = {"type"};
    if (phase.type == "hg" || phase.type == "mix") allowed.push_back("g");
    if (phase.type == "mix") allowed.push_back("a");
    if (phase.type == "eddington") allowed.push_back("b");
    for (const auto& [key, value] : j.items()) {
        if (std::find(allowed.begin(), allowed.end(), key) == allowed.end()) {
            std::string list;
            for (const std::string& k : allowed) list += (list.empty() ? "" : ", ") + k;
            throw InputError(InputLocation{"", 0, 0, "--phase." + key},
                             "unknown key for " + phase.type + "; allowed: " + list);
        }
        if (key != "type" && !value.is_number())
            throw InputError(InputLocation{"", 0, 0, "--phase." + key}, "must be a number");
    }
    phase.g = j.value("g", 0.0);
    phase.a = j.value("a", 1.0);
    phase.b = j.value("b", 0.0);
    if (!(phase.g > -1.0 && phase.g < 1.0))
        throw InputError(InputLocation{"", 0, 0, "--phase.g"}, "must be in (-1, 1), got " + j["g"].dump());
    if (!(phase.a >= 0.0 && phase.a <= 1.0))
        throw InputError(InputLocation{"", 0, 0, "--phase.a"}, "must be in [0, 1], got " + j["a"].dump());
    if (!(phase.b >= -1.0 && phase.b <= 1.0))
        throw InputError(InputLocation{"", 0, 0, "--phase.b"}, "must be in [-1, 1], got " + j["b"].dump());
    return phase;
}

std::vector<glm::dvec3> parsePolygon(const std::string& text) {
    const nlohmann::json j = parseArgument(text, "--polygon");
    const auto bad = [](const std::string& message) { return InputError(InputLocation{"", 0, 0, "--polygon"}, message); };
    if (!j.is_array() || j.size() < 3 || j.size() > size_t(shader::kLtsdMaxVertices - 1))
        throw bad("must be a list of 3 to " + std::to_string(shader::kLtsdMaxVertices - 1) + " directions [x,y,z]");
    std::vector<glm::dvec3> vertices;
    for (size_t i = 0; i < j.size(); ++i) {
        const nlohmann::json& v = j[i];
        if (!v.is_array() || v.size() != 3 || !v[0].is_number() || !v[1].is_number() || !v[2].is_number())
            throw bad("vertex " + std::to_string(i) + " must be [x, y, z]");
        const glm::dvec3 d(v[0].get<double>(), v[1].get<double>(), v[2].get<double>());
        // Scaled by its largest component first, so that any finite vector (1e308 included) normalises.
        const double largest = std::max({std::abs(d.x), std::abs(d.y), std::abs(d.z)});
        if (!std::isfinite(largest) || largest == 0.0)
            throw bad("vertex " + std::to_string(i) + " must be a finite, non-zero direction");
        vertices.push_back(glm::normalize(d / largest));
    }
    // Convex and inside an open hemisphere: every vertex on the inner side of every edge's great circle.
    double orientation = 0.0;
    for (size_t i = 0; i < vertices.size(); ++i) {
        const glm::dvec3 n = glm::cross(vertices[i], vertices[(i + 1) % vertices.size()]);
        for (size_t k = 0; k < vertices.size(); ++k) {
            if (k == i || k == (i + 1) % vertices.size()) continue;
            const double side = glm::dot(n, vertices[k]);
            if (orientation == 0.0) orientation = side > 0.0 ? 1.0 : -1.0;
            if (side * orientation <= 0.0) throw bad("the polygon must be convex and inside a hemisphere");
        }
    }
    return vertices;
}

// The tables in a folder, by file: <name>.ltsd (LTSD tables of phase functions) and <name>.ltc (LTC GGX tables).
struct TableFile {
    std::string name;
    std::filesystem::path path;
    bool ltc = false;
};

std::vector<TableFile> tablesIn(const std::filesystem::path& dir) {
    std::vector<TableFile> files;
    std::error_code ec;
    for (std::filesystem::directory_iterator it(dir, ec), end; !ec && it != end; it.increment(ec)) {
        const std::string ext = it->path().extension().string();
        if (ext == ".ltsd" || ext == ".ltc") files.push_back({it->path().stem().string(), it->path(), ext == ".ltc"});
    }
    // LTSD tables first (hg leads: the paper's), then LTC; by name within each.
    std::sort(files.begin(), files.end(), [](const TableFile& a, const TableFile& b) {
        const auto key = [](const TableFile& f) { return std::make_tuple(f.ltc, f.name != "hg", f.name); };
        return key(a) < key(b);
    });
    return files;
}

std::string listOf(const std::vector<TableFile>& files) {
    std::string list;
    for (const TableFile& f : files) list += (list.empty() ? "" : ", ") + f.name;
    return list.empty() ? "none" : list;
}

double number(const nlohmann::json& j, const char* key) {
    return j.contains(key) && j[key].is_number() ? j[key].get<double>() : std::nan("");
}

// The provenance lines that both kinds of table share (docs/tables.md, "Provenance").
void printProvenance(const std::string& path, const nlohmann::json& p) {
    if (p.is_null()) {
        std::printf("  no provenance (%s.json is missing)\n", path.c_str());
        return;
    }
    const nlohmann::json machine = p.value("machine", nlohmann::json::object());
    std::printf("  command:  %s\n  settings: %s\n  seed:     %s (%s)\n  fitted:   %s in %.2f s on %s (%s, %s threads)\n",
                p.value("command", "?").c_str(), p.value("settings", nlohmann::json()).dump().c_str(),
                p.value("seed", nlohmann::json()).dump().c_str(), p.value("seedNote", "").c_str(),
                p.value("date", "?").c_str(), p.value("fitSeconds", 0.0), machine.value("host", "?").c_str(),
                machine.value("cpu", "?").c_str(), machine.value("threadsUsed", nlohmann::json()).dump().c_str());
    if (p.contains("errorSummary"))
        std::printf("  total variation per entry: max %.3e, mean %.3e\n",
                    number(p["errorSummary"], "entryTotalVariationMax"), number(p["errorSummary"], "entryTotalVariationMean"));
}

// One table: its layout and provenance (and with `detail` the error summary's rows); the JSON form goes into `out`.
void describe(const TableFile& file, bool detail, bool json, nlohmann::json& out) {
    if (!file.ltc) {
        const LtsdTable table = loadLtsdTable(file.path, file.name);
        out.push_back({{"table", table.path},
                       {"kind", "ltsd"},
                       {"phase", table.phase},
                       {"entriesPerHalf", table.entriesPerHalf},
                       {"gRange", {-table.gMax, table.gMax}},
                       {"provenance", table.provenance}});
        if (json) return;
        if (table.entriesPerHalf == 1)
            std::printf("%s: LTSD table of %s, 2 x 1 entries (no parameter)\n", table.path.c_str(), table.phase.c_str());
        else
            std::printf("%s: LTSD table of %s, 2 x %d entries, g in [%.3f, %.3f] (beyond: clamped)\n",
                        table.path.c_str(), table.phase.c_str(), table.entriesPerHalf, -double(table.gMax),
                        double(table.gMax));
        printProvenance(table.path, table.provenance);
        const nlohmann::json& p = table.provenance;
        if (detail && p.contains("errorSummary") && p["errorSummary"].contains("againstG")) {
            std::printf("  %8s %12s %12s %12s\n", "g", "tv upper", "tv lower", "S bound");
            for (const auto& row : p["errorSummary"]["againstG"])
                std::printf("  %8.3f %12.3e %12.3e %12.3e\n", number(row, "g"), number(row, "tvUpper"),
                            number(row, "tvLower"), number(row, "bound"));
        }
        return;
    }
    const LtcTable table = loadLtcTable(file.path);
    nlohmann::json sizes = nlohmann::json::array();
    for (int d = 0; d < table.dimensions; ++d) sizes.push_back(table.sizes[size_t(d)]);
    out.push_back({{"table", table.path},
                   {"kind", "ltc"},
                   {"brdf", "ggx"},
                   {"anisotropic", !table.isotropicTable()},
                   {"sizes", sizes},
                   {"alphaRange", {table.alphaMin, 1.0}},
                   {"provenance", table.provenance}});
    if (json) return;
    if (table.isotropicTable())
        std::printf("%s: LTC table of GGX, isotropic, %d x %d entries over sqrt(1 - cos theta) in [0, 1] and alpha in "
                    "[%.3f, 1] (beyond: clamped)\n",
                    table.path.c_str(), table.xCount(), table.alphaCount(), double(table.alphaMin));
    else
        std::printf("%s: LTC table of GGX, anisotropic, %d x %d x %d x %d entries over theta_o, phi_o, alpha in "
                    "[%.3f, 1] and the roughness ratio in [%.3f, 1] (beyond: clamped)\n",
                    table.path.c_str(), table.thetaCount(), table.phiCount(), table.alphaCount(), table.ratioCount(),
                    double(table.alphaMin), double(table.ratioMin));
    printProvenance(table.path, table.provenance);
    const nlohmann::json& p = table.provenance;
    if (detail && p.contains("errorSummary") && p["errorSummary"].contains("againstAlpha")) {
        const bool aniso = !table.isotropicTable();
        std::printf(aniso ? "  %8s %8s %12s %12s\n" : "  %8s%s %12s %12s\n", "alpha", aniso ? "ratio" : "", "tv max",
                    "tv mean");
        for (const auto& row : p["errorSummary"]["againstAlpha"]) {
            if (aniso)
                std::printf("  %8.3f %8.3f %12.3e %12.3e\n", number(row, "alpha"), number(row, "ratio"),
                            number(row, "tvMax"), number(row, "tvMean"));
            else
                std::printf("  %8.3f %12.3e %12.3e\n", number(row, "alpha"), number(row, "tvMax"), number(row, "tvMean"));
        }
    }
}

}  // namespace

int tables(const TablesArgs& args) {
    return guarded([&] {
        const std::filesystem::path dir = ltsdTablesDirectory(args.tables);
        std::error_code ec;
        if (!std::filesystem::is_directory(dir, ec))
            throw InputError(InputLocation{dir.string(), 0, 0, "--tables"}, "is not a folder");
        const std::vector<TableFile> present = tablesIn(dir);
        std::vector<TableFile> chosen;
        if (args.names.empty()) {
            if (present.empty())
                throw InputError(InputLocation{dir.string(), 0, 0, "--tables"},
                                 "holds no tables (*.ltsd, *.ltc); the shipped ones are hg, rayleigh, hazy-mie, "
                                 "murky-mie, ggx and ggx-aniso");
            chosen = present;
        }
        for (const std::string& name : args.names) {
            const auto it = std::find_if(present.begin(), present.end(), [&](const TableFile& f) { return f.name == name; });
            if (it == present.end())
                throw InputError(InputLocation{dir.string(), 0, 0, "tables " + name},
                                 "no table named '" + name + "' (" + name + ".ltsd or " + name + ".ltc); this folder has: " +
                                     listOf(present));
            chosen.push_back(*it);
        }
        // Each table is loaded (and so checked) as it is described: a corrupt one fails the command with exit 2, after
        // the ones before it were printed.
        nlohmann::json out = nlohmann::json::array();
        const bool detail = !args.names.empty();
        for (size_t i = 0; i < chosen.size(); ++i) {
            if (!args.json && i > 0) std::printf("\n");
            describe(chosen[i], detail, args.json, out);
        }
        if (args.json) std::printf("%s\n", out.dump(2).c_str());
        return int(kOk);
    });
}

int tablesEval(const TablesEvalArgs& args) {
    return guarded([&] {
        const LtsdPhase phase = parsePhase(args.phase);
        const std::vector<glm::dvec3> vertices = parsePolygon(args.polygon);
        // Isotropic and Eddington are exact and read no table; mix reads HG's.
        const std::string tableType = ltsdTableFor(phase.type);
        LtsdTable table;
        if (!tableType.empty()) table = loadLtsdTable(ltsdTablePath(tableType, args.tables), tableType);
        const LtsdPhaseTerms terms = ltsdPhaseTerms(phase, tableType.empty() ? nullptr : &table);
        shader::SphericalPolygon polygon{};
        polygon.count = int(vertices.size());
        for (size_t i = 0; i < vertices.size(); ++i)
            polygon.v[i] = glm::vec3(vertices[i]);
        const double ltsd = ltsdPhaseIntegral(terms, polygon);
        // By the boundary form: exact, and quick for every g (a 2-D quadrature took 118 s at g = 0.9999999).
        const double exact = ltsdPhasePolygonIntegral(phase, vertices);
        const nlohmann::json j = {
            {"phase", {{"type", phase.type}, {"g", phase.g}, {"a", phase.a}, {"b", phase.b}}},
            {"frame", "omega_o = +z (towards the viewer); mu = -z"},
            {"table", tableType.empty() ? "none (exact)" : table.path},
            {"gClamped", !table.parameterless() && !tableType.empty() && std::abs(phase.g) > double(table.gMax)},
            {"exactPart", {{"isotropic", terms.isotropic}, {"linear", terms.linear}}},
            {"ltsd", ltsd},
            {"exact", exact},
            // Every S method (the LTSD technique's sMethod): the paper's Eq. 21 and the boundary form.
            {"sMethods", {{"paper", ltsd}, {"accurate", ltsdAccuratePhaseIntegral(phase, polygon)}}},
            {"absoluteError", ltsd - exact},
            {"relativeError", exact > 0.0 ? (ltsd - exact) / exact : 0.0},
            {"solidAngle", double(shader::ltsdSolidAngle(polygon))},
            {"clampedCosine", double(shader::ltsdClampedCosineIntegral(polygon))},
        };
        std::printf("%s\n", j.dump(2).c_str());
        return int(kOk);
    });
}

int plot(const PlotArgs& args) {
    return guarded([&] {
        const std::filesystem::path out(args.out);
        if (out.extension() != ".csv")
            throw InputError(InputLocation{"", 0, 0, "--out"},
                             "must end in .csv, got '" + args.out +
                                 "' (the studio's File > Export writes the drawn plots as PNG and SVG)");
        if (args.points < 0 || args.points == 1 || args.points > 1000000)
            throw InputError(InputLocation{"", 0, 0, "--points"}, "must be 0 (the default) or in [2, 1000000]");
        if (args.plot == "ltsd-polar" && !(args.g > -1.0 && args.g < 1.0))
            throw InputError(InputLocation{"", 0, 0, "--g"}, "must be in (-1, 1), got " + std::to_string(args.g));
        const LtsdTable table = loadLtsdTable(ltsdTablePath("hg", args.tables), "hg");
        std::string csv;
        char line[256];
        if (args.plot == "ltsd-polar") {
            // psi from omega_o (+z, towards the viewer); the fit's hemisphere, as its density jumps at the horizon.
            csv = "psi,phase,fitted,hemisphere\n";
            for (const LtsdPolarPoint& p : ltsdPolarCurve(table, args.g, args.points > 0 ? args.points : 720)) {
                std::snprintf(line, sizeof line, "%.9g,%.9g,%.9g,%s\n", p.psi, p.phase, p.fitted,
                              std::cos(p.psi) > 0.0 ? "upper" : "lower");
                csv += line;
            }
        } else {
            csv = "g,tvUpper,tvLower,bound\n";
            for (const LtsdFitError& e : ltsdFitErrorCurve(table, args.points > 0 ? args.points : 101)) {
                std::snprintf(line, sizeof line, "%.9g,%.9g,%.9g,%.9g\n", e.g, e.tvUpper, e.tvLower, e.bound);
                csv += line;
            }
        }
        // All or nothing, through an unpredictable temporary (docs/conventions.md, "Exit codes, outputs and limits").
        writeFileAtomically(args.out, csv);
        return int(kOk);
    });
}

}  // namespace tyndall::cli
