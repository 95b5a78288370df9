// `tyndall tables` and `tyndall tables eval`: the fitted LTSD tables' provenance and error summary, and a probe of the
// fit over any spherical polygon (docs/tables.md); `tyndall plot ltsd-polar|ltsd-error`: the studio's LTSD plots' data.
#include "commands.h"

#include "tyndall/error.h"
#include "tyndall/ltsd_table.h"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>

namespace tyndall::cli {

namespace {

int reportErrors(const std::function<int()>& body) {
    try {
        return body();
    } catch (const InputError& e) {
        std::fprintf(stderr, "tyndall: error: %s\n", e.what());
        return kBadInput;
    } catch (const std::exception& e) {
        std::fprintf(stderr, "tyndall: failure: %s\n", e.what());
        return kFailure;
    }
}

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
        if (!std::isfinite(glm::length(d)) || glm::length(d) == 0.0)
            throw bad("vertex " + std::to_string(i) + " must be a finite, non-zero direction");
        vertices.push_back(glm::normalize(d));
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

}  // namespace

int tables(const TablesArgs& args) {
    return reportErrors([&] {
        const LtsdTable table = loadLtsdTable(ltsdTablePath("hg", args.tables));
        nlohmann::json j = {{"table", table.path},
                            {"phase", table.phase},
                            {"entriesPerHalf", table.entriesPerHalf},
                            {"gRange", {-table.gMax, table.gMax}},
                            {"provenance", table.provenance}};
        if (args.json) {
            std::printf("%s\n", j.dump(2).c_str());
            return int(kOk);
        }
        const nlohmann::json& p = table.provenance;
        std::printf("%s: LTSD table of %s, 2 x %d entries, g in [%.3f, %.3f] (beyond: clamped)\n", table.path.c_str(),
                    table.phase.c_str(), table.entriesPerHalf, -double(table.gMax), double(table.gMax));
        if (p.is_null()) {
            std::printf("  no provenance (%s.json is missing)\n", table.path.c_str());
            return int(kOk);
        }
        std::printf("  command:  %s\n  settings: %s\n  seed:     %s (%s)\n  fitted:   %s in %.2f s on %s (%s, %s threads)\n",
                    p.value("command", "?").c_str(), p.value("settings", nlohmann::json()).dump().c_str(),
                    p.value("seed", nlohmann::json()).dump().c_str(), p.value("seedNote", "").c_str(),
                    p.value("date", "?").c_str(), p.value("fitSeconds", 0.0), p["machine"].value("host", "?").c_str(),
                    p["machine"].value("cpu", "?").c_str(), p["machine"].value("threadsUsed", nlohmann::json()).dump().c_str());
        if (p.contains("errorSummary")) {
            const nlohmann::json& e = p["errorSummary"];
            std::printf("  total variation per entry: max %.3e, mean %.3e\n", e.value("entryTotalVariationMax", 0.0),
                        e.value("entryTotalVariationMean", 0.0));
            std::printf("  %8s %12s %12s %12s\n", "g", "tv upper", "tv lower", "S bound");
            for (const auto& row : e["againstG"])
                std::printf("  %8.3f %12.3e %12.3e %12.3e\n", row["g"].get<double>(), row["tvUpper"].get<double>(),
                            row["tvLower"].get<double>(), row["bound"].get<double>());
        }
        return int(kOk);
    });
}

int tablesEval(const TablesEvalArgs& args) {
    return reportErrors([&] {
        const LtsdPhase phase = parsePhase(args.phase);
        const std::vector<glm::dvec3> vertices = parsePolygon(args.polygon);
        // Isotropic and Eddington are exact and read no table; mix reads HG's.
        const std::string tableType = ltsdTableFor(phase.type);
        LtsdTable table;
        if (!tableType.empty()) table = loadLtsdTable(ltsdTablePath(tableType, args.tables));
        const LtsdPhaseTerms terms = ltsdPhaseTerms(phase, tableType.empty() ? nullptr : &table);
        shader::SphericalPolygon polygon{};
        polygon.count = int(vertices.size());
        glm::dvec3 centre(0.0);
        for (size_t i = 0; i < vertices.size(); ++i) {
            polygon.v[i] = glm::vec3(vertices[i]);
            centre += vertices[i];
        }
        const double ltsd = ltsdPhaseIntegral(terms, polygon);
        const double exact =
            integrateOverSphericalPolygon(vertices, centre, [&](const glm::dvec3& w) { return phase.eval(-w.z); });
        const nlohmann::json j = {
            {"phase", {{"type", phase.type}, {"g", phase.g}, {"a", phase.a}, {"b", phase.b}}},
            {"frame", "omega_o = +z (towards the viewer); mu = -z"},
            {"table", tableType.empty() ? "none (exact)" : table.path},
            {"gClamped", !table.parameterless() && !tableType.empty() && std::abs(phase.g) > double(table.gMax)},
            {"exactPart", {{"isotropic", terms.isotropic}, {"linear", terms.linear}}},
            {"ltsd", ltsd},
            {"exact", exact},
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
    return reportErrors([&] {
        const std::filesystem::path out(args.out);
        if (out.extension() != ".csv")
            throw InputError(InputLocation{"", 0, 0, "--out"},
                             "must end in .csv, got '" + args.out +
                                 "' (the studio's File > Export writes the drawn plots as PNG and SVG)");
        if (args.points < 0 || args.points == 1 || args.points > 1000000)
            throw InputError(InputLocation{"", 0, 0, "--points"}, "must be 0 (the default) or in [2, 1000000]");
        if (args.plot == "ltsd-polar" && !(args.g > -1.0 && args.g < 1.0))
            throw InputError(InputLocation{"", 0, 0, "--g"}, "must be in (-1, 1), got " + std::to_string(args.g));
        const LtsdTable table = loadLtsdTable(ltsdTablePath("hg", args.tables));
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
        // Atomically, so that a failed write leaves no partial file.
        const std::filesystem::path partial = out.string() + ".partial";
        {
            std::ofstream file(partial, std::ios::binary);
            file << csv;
            file.close();
            if (!file) {
                std::error_code ec;
                std::filesystem::remove(partial, ec);
                throw std::runtime_error("cannot write " + args.out);
            }
        }
        std::error_code ec;
        std::filesystem::rename(partial, out, ec);
        if (ec) throw std::runtime_error("cannot write " + args.out + ": " + ec.message());
        return int(kOk);
    });
}

}  // namespace tyndall::cli
