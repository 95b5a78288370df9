// tyndall-fit-tables: fits the LTSD tables of Henyey-Greenstein and other phase functions' lobes, and with --ltc the
// LTC GGX table (docs/tables.md), and writes them with their provenance, or with --check re-fits entries and compares
// them bit for bit with a shipped table.
#include "fit.h"
#include "ltc_fit.h"

#include "tyndall/core/error.h"

#include <CLI/CLI.hpp>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <ctime>
#include <fstream>
#include <thread>
#include <unistd.h>

namespace {

using namespace tyndall;

std::string cpuModel() {
    std::ifstream in("/proc/cpuinfo");
    std::string line;
    while (std::getline(in, line))
        if (line.rfind("model name", 0) == 0) return line.substr(line.find(':') + 2);
    return "unknown";
}

std::string hostName() {
    char name[256] = {};
    return gethostname(name, sizeof name - 1) == 0 ? name : "unknown";
}

std::string utcNow() {
    std::time_t t = std::time(nullptr);
    char text[32];
    std::strftime(text, sizeof text, "%Y-%m-%dT%H:%M:%SZ", std::gmtime(&t));
    return text;
}

nlohmann::json errorSummary(const LtsdTable& table) {
    double maxTv = 0.0, sumTv = 0.0;
    for (int i = 0; i < int(table.entries.size()); ++i) {
        const shader::LtsdEntry& e = table.entries[size_t(i)];
        const double tv = table.parameterless()
                              ? ltsdLobeTotalVariation(table.phase, 0.0, i == 0 ? 1 : -1, e.source,
                                                       double(e.m[0]) / double(e.m[8]))
                              : ltsdTotalVariation(table.entryG(i), e.source, double(e.m[0]) / double(e.m[8]));
        maxTv = std::max(maxTv, tv);
        sumTv += tv;
    }
    nlohmann::json curve = nlohmann::json::array();
    for (const LtsdFitError& e : ltsdFitErrorCurve(table, 21))
        curve.push_back({{"g", e.g}, {"tvUpper", e.tvUpper}, {"tvLower", e.tvLower}, {"bound", e.bound}});
    return {{"entryTotalVariationMax", maxTv},
            {"entryTotalVariationMean", sumTv / double(table.entries.size())},
            {"note", "total-variation distance per hemisphere (in [0, 2]); 'bound' = (a_u tv_u + a_l tv_l) / 2 bounds "
                     "the absolute error of S over any region; polygon errors against quadrature: docs/tables.md"},
            {"againstG", curve}};
}

// The load average (1, 5, 15 minutes) when the fitter starts: the machine is shared, and wall times depend on it.
std::string loadAverage() {
    std::ifstream in("/proc/loadavg");
    std::string one, five, fifteen;
    in >> one >> five >> fifteen;
    return in ? one + " " + five + " " + fifteen : "unknown";
}

const std::string kLoadAtStart = loadAverage();

nlohmann::json machine(int threads) {
    return {{"host", hostName()},
            {"loadAverageAtStart", kLoadAtStart},
            {"cpu", cpuModel()},
            {"hardwareThreads", std::thread::hardware_concurrency()},
            {"threadsUsed", threads > 0 ? threads : int(std::thread::hardware_concurrency())}};
}

std::string commandLine(int argc, char** argv) {
    std::string command;
    for (int i = 0; i < argc; ++i) command += (i ? " " : "") + std::string(argv[i]);
    return command;
}

// The LTC table's error summary: the stored total-variation distance per entry, its maximum and mean per row (alpha;
// anisotropic: alpha and r).
nlohmann::json ltcErrorSummary(const LtcTable& table, const tables::LtcFitSettings& settings) {
    double maxTv = 0.0, sumTv = 0.0;
    nlohmann::json rows = nlohmann::json::array();
    const int length = tables::ltcRowLength(settings), rowCount = tables::ltcEntryCount(settings) / length;
    for (int row = 0; row < rowCount; ++row) {
        double rowMax = 0.0, rowSum = 0.0;
        for (int j = 0; j < length; ++j) {
            const double tv = table.entries[size_t(row * length + j)].error;
            rowMax = std::max(rowMax, tv);
            rowSum += tv;
        }
        maxTv = std::max(maxTv, rowMax);
        sumTv += rowSum;
        const int ia = row % table.alphaCount();
        nlohmann::json summary = {{"alpha", LtcTable::gridAlpha(ia, table.alphaCount(), table.alphaMin)},
                                  {"tvMax", rowMax},
                                  {"tvMean", rowSum / length}};
        if (!table.isotropicTable())
            summary["ratio"] = LtcTable::gridRatio(row / table.alphaCount(), table.ratioCount(), table.ratioMin);
        rows.push_back(summary);
    }
    return {{"entryTotalVariationMax", maxTv},
            {"entryTotalVariationMean", sumTv / double(table.entries.size())},
            {"note", "total-variation distance int |p - q| (in [0, 2]) between GGX's normalised lobe and the LTC, "
                     "estimated with momentSamples visible-normal and LTC samples; any polygon's normalised integral "
                     "is off by at most tv / 2; polygon errors against quadrature: docs/tables.md"},
            {"againstAlpha", rows}};
}

// tyndall-fit-tables --ltc: fit (or with --check re-fit and compare) the isotropic LTC GGX table.
int runLtc(tables::LtcFitSettings settings, const std::string& out, const std::string& check, bool quick, int argc,
           char** argv) {
    LtcTable reference;
    if (!check.empty()) {
        reference = loadLtcTable(check);
        if (reference.provenance.contains("settings"))
            tables::ltcSettingsFromJson(reference.provenance["settings"], settings);
        if (int(reference.entries.size()) != tables::ltcEntryCount(settings) ||
            reference.isotropicTable() == settings.anisotropic) {
            std::fprintf(stderr, "tyndall-fit-tables: %s: has %zu entries, the settings %d\n", check.c_str(),
                         reference.entries.size(), tables::ltcEntryCount(settings));
            return 1;
        }
    }
    const bool terminal = isatty(fileno(stderr));
    const auto start = std::chrono::steady_clock::now();
    if (!check.empty()) {
        // Each entry depends only on stored entries before it in its row (ltc_fit.h), so entries are re-fitted from the
        // shipped predecessors: all of them, or with --quick a few per row in four rows. Anisotropic: the quick entries
        // cover every kind (theta = 0, phi = 0, general, phi = pi / 2).
        std::vector<int> indices;
        const int length = tables::ltcRowLength(settings), rows = tables::ltcEntryCount(settings) / length;
        const int nt = settings.thetaCount;
        const std::vector<int> quickPositions =
            settings.anisotropic ? std::vector<int>{0, 1, nt - 1, nt + 3, (length / 2) + nt / 2, length - 1}
                                 : std::vector<int>{0, 1, length / 2, length - 1};
        for (int row = 0; row < rows; ++row)
            for (int j = 0; j < length; ++j) {
                const bool quickRow = row == 0 || row == rows / 3 || row == (2 * rows) / 3 || row == rows - 1;
                const bool pick = !quick || (quickRow && std::find(quickPositions.begin(), quickPositions.end(), j) !=
                                                             quickPositions.end());
                if (pick) indices.push_back(row * length + j);
            }
        const auto stored = [&](int i) -> const shader::LtcEntry& { return reference.entries[size_t(i)]; };
        int differing = 0;
        for (size_t k = 0; k < indices.size(); ++k) {
            const int i = indices[k];
            const shader::LtcEntry e =
                settings.anisotropic
                    ? tables::fitLtcAnisotropicEntry(i, settings, stored)
                    : tables::fitLtcEntry(i, settings, i % length > 0 ? &reference.entries[size_t(i - 1)] : nullptr);
            if (std::memcmp(&e, &reference.entries[size_t(i)], sizeof e) != 0) {
                ++differing;
                std::fprintf(stderr, "entry %d: m00 = %.9g, shipped %.9g; error %.6g, shipped %.6g\n", i,
                             double(e.m[0]), double(reference.entries[size_t(i)].m[0]), double(e.error),
                             double(reference.entries[size_t(i)].error));
            }
            if (terminal) std::fprintf(stderr, "\rre-fitting: %zu / %zu", k + 1, indices.size());
        }
        if (terminal) std::fprintf(stderr, "\n");
        std::printf("%d of %zu re-fitted entries differ from %s\n", differing, indices.size(), check.c_str());
        return differing == 0 ? 0 : 1;
    }
    int lastReported = -1;
    const auto progress = [&](int done, int total) {
        if (done == lastReported) return;
        lastReported = done;
        const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
        std::fprintf(stderr, "%sfitting %s LTC: %d / %d entries, %.1f s%s", terminal ? "\r" : "",
                     settings.anisotropic ? "anisotropic GGX" : "GGX", done, total, seconds,
                     terminal && done < total ? "" : "\n");
    };
    const int length = tables::ltcRowLength(settings), rowCount = tables::ltcEntryCount(settings) / length;
    std::vector<int> rows;
    if (quick)
        for (int row = 0; row < rowCount; row += 16)
            rows.push_back(row);
    LtcTable table;
    table.dimensions = settings.anisotropic ? 4 : 2;
    table.sizes = settings.anisotropic
                      ? std::array<int, 4>{settings.thetaCount, settings.phiCount, settings.alphaCount,
                                           settings.ratioCount}
                      : std::array<int, 4>{settings.xCount, settings.alphaCount, 1, 1};
    table.alphaMin = settings.alphaMin;
    table.ratioMin = settings.anisotropic ? settings.ratioMin : 0.0f;
    table.entries = tables::fitLtcRows(settings, rows, progress);
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    if (quick) {  // a partial table cannot be loaded (zero matrices): fill the missing rows by copying, and say so
        for (int row = 0; row < rowCount; ++row)
            if (row % 16 != 0)
                for (int j = 0; j < length; ++j)
                    table.entries[size_t(row * length + j)] = table.entries[size_t((row - row % 16) * length + j)];
    }
    table.provenance = {
        {"format", "docs/tables.md"},
        {"brdf", std::string("GGX, height-correlated Smith, F = 1 (Schlick applied at run time from norm and "
                             "fresnel); ") +
                     (settings.anisotropic ? "anisotropic (002)" : "isotropic")},
        {"source", "clamped cosine"},
        {"command", commandLine(argc, argv)},
        {"seed", 0},
        {"seedNote", "the fit draws no random numbers (fixed golden-ratio lattices, deterministic Nelder-Mead)"},
        {"settings", tables::ltcSettingsToJson(settings)},
        {"partial", quick},
        {"fitSeconds", seconds},
        {"cpuSeconds", double(std::clock()) / CLOCKS_PER_SEC},
        {"machine", machine(settings.threads)},
        {"date", utcNow()},
        {"fitter", "tyndall-fit-tables " TYNDALL_VERSION},
    };
    if (!quick) table.provenance["errorSummary"] = ltcErrorSummary(table, settings);
    saveLtcTable(table, out);
    std::printf("wrote %s (%zu entries, %.1f s)\n", out.c_str(), table.entries.size(), seconds);
    return 0;
}

}  // namespace

int main(int argc, char** argv) {
    CLI::App app{"tyndall-fit-tables: fit the LTSD tables of Henyey-Greenstein and of the lobes of Rayleigh and the Mie "
                 "presets (docs/tables.md)"};
    tables::FitSettings settings;
    tables::LtcFitSettings ltcSettings;
    std::string out, check;
    bool quick = false, ltc = false;
    app.add_flag("--ltc", ltc, "fit the LTC GGX table instead (docs/tables.md, \"LTC GGX tables\"); implied by "
                               "--check FILE.ltc");
    bool aniso = false;
    app.add_flag("--aniso", aniso, "with --ltc: the anisotropic table of 002 (theta, phi, alpha, r; 8^4 entries)");
    app.add_option("--ltc-size", ltcSettings.xCount,
                   "--ltc: entries over sqrt(1 - cos theta) and over alpha (64); --aniso: per dimension (8)")
        ->check(CLI::Range(2, 4096));
    app.add_option("--ltc-samples", ltcSettings.samples, "--ltc: samples per strategy of the loss")
        ->check(CLI::Range(16, 1 << 20));
    app.add_option("--out,-o", out, "the table to write (its provenance goes to <out>.json)");
    app.add_option("--phase", settings.phase,
                   "hg (a table over g), or a parameterless lobe: rayleigh, hazy-mie, murky-mie (docs/tables.md)")
        ->check(CLI::IsMember({"hg", "rayleigh", "hazy-mie", "murky-mie"}));
    app.add_option("--loss", settings.loss, "sw (sliced Wasserstein, 002 Sec. 4; the default) or tv (total variation)")
        ->check(CLI::IsMember({"tv", "sw"}));
    app.add_option("--entries", settings.entriesPerHalf, "entries per half of the table (T_1, T_2)")
        ->check(CLI::Range(2, 65536));
    app.add_option("--gmax", settings.gMax, "the table covers g in [-gmax, gmax]")->check(CLI::Range(0.01, 0.999));
    app.add_option("--sw-samples", settings.swSamples, "sw: samples per distribution")->check(CLI::Range(16, 1 << 20));
    app.add_option("--sw-directions", settings.swDirections, "sw: projection directions")->check(CLI::Range(1, 4096));
    app.add_option("--threads", settings.threads, "threads (0: all)")->check(CLI::Range(0, 1024));
    app.add_flag("--quick", quick, "fit every 16th entry and both ends of each half only (with --check: a quick test)");
    app.add_option("--check", check, "re-fit and compare bit for bit with this table instead of writing one");
    try {
        app.parse(argc, argv);
    } catch (const CLI::ParseError& e) {
        const int code = app.exit(e);
        return code == 0 ? 0 : 2;
    }
    if (out.empty() && check.empty()) {
        std::fprintf(stderr, "tyndall-fit-tables: error: give --out FILE or --check FILE\n");
        return 2;
    }
    try {
        if (ltc || (check.size() > 4 && check.compare(check.size() - 4, 4, ".ltc") == 0)) {
            ltcSettings.anisotropic = aniso;
            if (aniso && app.count("--ltc-size") == 0) ltcSettings.xCount = 8;
            ltcSettings.alphaCount = ltcSettings.xCount;
            ltcSettings.thetaCount = ltcSettings.phiCount = ltcSettings.ratioCount = ltcSettings.xCount;
            ltcSettings.threads = settings.threads;
            return runLtc(ltcSettings, out, check, quick, argc, argv);
        }
        std::vector<int> indices;
        LtsdTable reference;
        if (!check.empty()) {
            reference = loadLtsdTable(check);
            if (reference.provenance.contains("settings")) {
                const nlohmann::json& s = reference.provenance["settings"];
                settings.phase = s.value("phase", settings.phase);
                settings.loss = s.value("loss", settings.loss);
                settings.entriesPerHalf = s.value("entriesPerHalf", settings.entriesPerHalf);
                settings.gMax = s.value("gMax", settings.gMax);
                settings.swSamples = s.value("swSamples", settings.swSamples);
                settings.swDirections = s.value("swDirections", settings.swDirections);
            }
        }
        if (settings.phase != "hg") settings.entriesPerHalf = 1, settings.gMax = 0.0f;
        const int n = settings.entriesPerHalf;
        if (quick && n > 1)
            for (int i = 0; i < 2 * n; ++i)
                if (i % 16 == 0 || i == n - 1 || i == 2 * n - 1) indices.push_back(i);
        const bool terminal = isatty(fileno(stderr));
        const auto start = std::chrono::steady_clock::now();
        int lastReported = -1;
        const auto progress = [&](int done, int total) {
            if (done == lastReported) return;  // a line per finished entry, not per poll, when logged to a file
            lastReported = done;
            const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
            std::fprintf(stderr, "%sfitting %s (%s): %d / %d entries, %.1f s%s", terminal ? "\r" : "",
                         settings.phase.c_str(), settings.loss.c_str(), done, total, seconds, terminal && done < total ? "" : "\n");
        };
        const std::vector<shader::LtsdEntry> entries = tables::fitEntries(settings, indices, progress);
        const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();

        if (!check.empty()) {
            if (reference.entriesPerHalf != settings.entriesPerHalf) {
                std::fprintf(stderr, "tyndall-fit-tables: %s: has %d entries per half, the settings %d\n",
                             check.c_str(), reference.entriesPerHalf, settings.entriesPerHalf);
                return 1;
            }
            int compared = 0, differing = 0;
            for (int i = 0; i < 2 * n; ++i) {
                if (!indices.empty() && std::find(indices.begin(), indices.end(), i) == indices.end()) continue;
                ++compared;
                if (std::memcmp(&entries[size_t(i)], &reference.entries[size_t(i)], sizeof(shader::LtsdEntry)) != 0) {
                    ++differing;
                    std::fprintf(stderr, "entry %d (g = %.6f): m = %.9g, shipped %.9g\n", i, double(entries[size_t(i)].g),
                                 double(entries[size_t(i)].m[0]), double(reference.entries[size_t(i)].m[0]));
                }
            }
            std::printf("%d of %d re-fitted entries differ from %s\n", differing, compared, check.c_str());
            return differing == 0 ? 0 : 1;
        }

        LtsdTable table;
        table.phase = settings.phase;
        table.entriesPerHalf = n;
        table.gMax = settings.gMax;
        table.entries = entries;
        const std::string command = commandLine(argc, argv);
        table.provenance = {
            {"format", "docs/tables.md"},
            {"phase", settings.phase},
            {"command", command},
            {"seed", 0},
            {"seedNote", "the fit draws no random numbers (fixed quadrature, fixed quasi-random samples)"},
            {"settings", tables::settingsToJson(settings)},
            {"partial", quick},
            {"fitSeconds", seconds},
            {"machine", machine(settings.threads)},
            {"date", utcNow()},
            {"fitter", "tyndall-fit-tables " TYNDALL_VERSION},
        };
        const bool partial = quick && n > 1;
        table.provenance["partial"] = partial;
        if (!partial) table.provenance["errorSummary"] = errorSummary(table);
        if (partial) {  // a partial table cannot be loaded (zero matrices): fill the gaps by copying, and say so
            for (int i = 0; i < 2 * n; ++i)
                if (table.entries[size_t(i)].m[8] == 0.0f) {
                    int j = i;
                    while (table.entries[size_t(j)].m[8] == 0.0f) --j;
                    table.entries[size_t(i)] = table.entries[size_t(j)];
                }
        }
        saveLtsdTable(table, out);
        std::printf("wrote %s (%d entries, %.1f s)\n", out.c_str(), 2 * n, seconds);
        return 0;
    } catch (const InputError& e) {
        std::fprintf(stderr, "tyndall-fit-tables: error: %s\n", e.what());
        return 2;
    }
}
