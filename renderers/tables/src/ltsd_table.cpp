#include "tyndall/tables/ltsd_table.h"

#include "shared/ltsd_boundary.h"

#include "table_file.h"
#include "tyndall/core/resources.h"
#include "tyndall/core/text.h"

#include "tyndall/core/error.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <iterator>
#include <limits>
#include <system_error>

namespace tyndall {

namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr char kMagic[8] = {'T', 'Y', 'L', 'T', 'S', 'D', '\r', '\n'};
constexpr std::size_t kHeaderBytes = 64;
constexpr std::size_t kEntryBytes = sizeof(shader::LtsdEntry);
static_assert(kEntryBytes == 48, "LtsdEntry must match its std430 layout (docs/tables.md)");

using table_file::get;
using table_file::hex64;
using table_file::kChecksumOffset;
using table_file::put;
using table_file::writeAtomically;

// 8-point Gauss-Legendre nodes and weights on [-1, 1].
constexpr std::array<double, 4> kGaussNodes = {0.1834346424956498, 0.5255324099163290, 0.7966664774136267,
                                               0.9602898564975363};
constexpr std::array<double, 4> kGaussWeights = {0.3626837833783620, 0.3137066458778873, 0.2223810344533745,
                                                 0.1012285362903763};

// The densities in x = ln tan(theta) over the upper hemisphere (docs/tables.md): each integrates to 1 over the real
// line. With t = e^x: sin^2 = t^2 / (1 + t^2), cos = 1 / sqrt(1 + t^2).
double sourceDensityX(int source, double x) {
    const double t2 = std::exp(2.0 * x);
    const double s2 = t2 / (1.0 + t2);
    const double c = 1.0 / std::sqrt(1.0 + t2);
    return source == shader::kLtsdSourceClampedCosine ? 2.0 * s2 * c * c : 2.0 * s2 * c * (1.0 - c);
}

double hgUpperDensityX(double g, double x) {
    const double t2 = std::exp(2.0 * x);
    const double s2 = t2 / (1.0 + t2);
    const double c = 1.0 / std::sqrt(1.0 + t2);
    return 2.0 * kPi * s2 * c * LtsdPhase{"hg", g}.eval(-c) / hgUpperAmplitude(g);
}

double hgEval(double g, double mu) {
    const double d = 1.0 + g * g - 2.0 * g * mu;
    return (1.0 - g * g) / (4.0 * kPi * d * std::sqrt(d));
}

int mieExponent(const std::string& type) {
    return type == "hazy-mie" ? 8 : 32;
}

bool isMie(const std::string& type) {
    return type == "hazy-mie" || type == "murky-mie";
}

}  // namespace

double LtsdPhase::eval(double mu) const {
    if (type == "hg") return hgEval(g, mu);
    if (type == "isotropic") return 1.0 / (4.0 * kPi);
    if (type == "mix") return (1.0 - a) / (4.0 * kPi) + a * hgEval(g, mu);
    if (type == "eddington") return (1.0 + b * mu) / (4.0 * kPi);
    if (type == "rayleigh" || isMie(type))
        return (1.0 - ltsdLobeWeight(type)) / (4.0 * kPi) + ltsdLobeWeight(type) * ltsdLobeEval(type, g, mu);
    TY_CHECK(false, "LtsdPhase: unknown phase type " + type);
    return 0.0;
}

double LtsdPhase::cdf(double mu) const {
    const double isotropic = 0.5 * (1.0 + mu);
    if (type == "hg") return ltsdLobeCdf("hg", g, mu);
    if (type == "isotropic") return isotropic;
    if (type == "mix") return (1.0 - a) * isotropic + a * ltsdLobeCdf("hg", g, mu);
    if (type == "eddington") return isotropic + 0.25 * b * (mu * mu - 1.0);
    if (type == "rayleigh" || isMie(type))
        return (1.0 - ltsdLobeWeight(type)) * isotropic + ltsdLobeWeight(type) * ltsdLobeCdf(type, g, mu);
    TY_CHECK(false, "LtsdPhase: unknown phase type " + type);
    return 0.0;
}

std::string ltsdTableFor(const std::string& type) {
    if (type == "hg" || type == "mix") return "hg";
    if (type == "rayleigh" || isMie(type)) return type;
    if (type == "isotropic" || type == "eddington") return "";
    throw InputError(InputLocation{"", 0, 0, "phase.type"},
                     "'" + type + "' has no LTSD form (tables exist for hg, mix, rayleigh, hazy-mie, murky-mie; "
                     "isotropic and eddington are exact)");
}

double ltsdLobeEval(const std::string& type, double g, double mu) {
    if (type == "hg") return hgEval(g, mu);
    if (type == "rayleigh") return 3.0 * mu * mu / (4.0 * kPi);
    TY_CHECK(isMie(type), "no lobe for " + type);
    const int n = mieExponent(type);
    return double(n + 1) * std::pow(std::max(0.0, 0.5 * (1.0 + mu)), n) / (4.0 * kPi);
}

double ltsdLobeCdf(const std::string& type, double g, double mu) {
    if (type == "hg") {
        if (std::abs(g) < 1e-6) return 0.5 * (1.0 + mu);
        return (1.0 - g * g) / (2.0 * g) * (1.0 / std::sqrt(1.0 + g * g - 2.0 * g * mu) - 1.0 / (1.0 + g));
    }
    if (type == "rayleigh") return 0.5 * (mu * mu * mu + 1.0);
    TY_CHECK(isMie(type), "no lobe for " + type);
    return std::pow(std::max(0.0, 0.5 * (1.0 + mu)), mieExponent(type) + 1);
}

double ltsdLobeWeight(const std::string& type) {
    if (type == "hg") return 1.0;
    if (type == "rayleigh") return 0.25;
    TY_CHECK(isMie(type), "no lobe for " + type);
    return 0.5;
}

namespace {

// The lobe's density in x = ln tan(theta) over one hemisphere (side +1: upper, mu = -cos; -1: lower mirrored, mu = cos),
// normalised to 1 like sourceDensityX.
double lobeDensityX(const std::string& type, double g, int side, double amplitude, double x) {
    const double t2 = std::exp(2.0 * x);
    const double s2 = t2 / (1.0 + t2);
    const double c = 1.0 / std::sqrt(1.0 + t2);
    return 2.0 * kPi * s2 * c * ltsdLobeEval(type, g, -double(side) * c) / amplitude;
}

}  // namespace

double LtsdTable::isotropicWeight() const {
    if (!parameterless()) return 0.0;
    return std::max(0.0, 1.0 - double(entries[0].amplitude) - double(entries[1].amplitude));
}

LtsdPhaseTerms ltsdPhaseTerms(const LtsdPhase& phase, const LtsdTable* table) {
    LtsdPhaseTerms t;
    const std::string tableType = ltsdTableFor(phase.type);
    if (phase.type == "isotropic") {
        t.isotropic = 1.0f;
        return t;
    }
    if (phase.type == "eddington") {
        t.isotropic = 1.0f;
        t.linear = float(phase.b);
        return t;
    }
    TY_CHECK(table != nullptr && table->phase == tableType, "ltsdPhaseTerms needs the " + tableType + " table");
    t.upper = table->upper(phase.g);
    t.lower = table->lower(phase.g);
    t.isotropic = float(table->isotropicWeight());
    if (phase.type == "mix") {
        t.upper.amplitude *= float(phase.a);
        t.lower.amplitude *= float(phase.a);
        t.isotropic = float(1.0 - phase.a);
    }
    return t;
}

std::string ltsdPhaseRefusal(const std::string& type) {
    for (const LtsdPhaseQuality& q : kLtsdPhaseQuality) {
        if (type != q.type) continue;
        if (q.maxAbs <= kLtsdAcceptedMaxAbs && q.meanAbs <= kLtsdAcceptedMeanAbs) return "";
        char text[320];
        std::snprintf(text, sizeof text,
                      "its LTSD fit's error over the test polygons (max %.3g, mean %.3g absolute) exceeds the "
                      "threshold (max %.3g, mean %.3g: the HG table's worst; docs/tables.md)",
                      q.maxAbs, q.meanAbs, kLtsdAcceptedMaxAbs, kLtsdAcceptedMeanAbs);
        return text;
    }
    return "it has no LTSD form (tables exist for hg, mix, rayleigh, hazy-mie and murky-mie; isotropic and "
           "eddington are exact)";
}

double ltsdPhaseIntegral(const LtsdPhaseTerms& t, const shader::SphericalPolygon& polygon) {
    return double(shader::ltsdPhaseIntegral(polygon, t.upper, t.lower, t.isotropic, t.linear));
}

LtsdBoundaryTerms ltsdBoundaryTerms(const LtsdPhase& phase) {
    // The lobe is the one a table would fit (ltsdTableFor throws for a type without an LTSD form); isotropic and
    // eddington have none and are exact.
    LtsdBoundaryTerms t;
    const std::string lobeType = ltsdTableFor(phase.type);
    if (lobeType.empty()) {
        t.isotropic = 1.0f;
        t.linear = phase.type == "eddington" ? float(phase.b) : 0.0f;
        return t;
    }
    t.lobe = lobeType == "hg"         ? shader::kLtsdLobeHg
             : lobeType == "rayleigh" ? shader::kLtsdLobeRayleigh
                                      : (mieExponent(lobeType) == 8 ? shader::kLtsdLobeMie8 : shader::kLtsdLobeMie32);
    t.g = lobeType == "hg" ? float(phase.g) : 0.0f;
    const double weight = phase.type == "mix" ? phase.a : ltsdLobeWeight(lobeType);
    t.lobeWeight = float(weight);
    t.isotropic = float(1.0 - weight);
    return t;
}

double ltsdAccuratePhaseIntegral(const LtsdPhase& phase, const shader::SphericalPolygon& polygon) {
    const LtsdBoundaryTerms t = ltsdBoundaryTerms(phase);
    return double(shader::ltsdAccuratePhaseIntegral(polygon, t.lobe, t.g, t.lobeWeight, t.isotropic, t.linear));
}

double hgUpperAmplitude(double g) {
    const double r = std::sqrt(1.0 + g * g);
    return (1.0 - g) / (r * (1.0 + g + r));
}

// ---------------------------------------------------------------------------------------------------------------------
// Fetch and evaluation

double LtsdTable::entryG(int i) const {
    const int n = entriesPerHalf;
    if (i < n) return -double(gMax) + double(gMax) * double(i) / double(n - 1);
    return double(gMax) * double(i - n) / double(n - 1);
}

shader::LtsdEntry LtsdTable::upper(double g) const {
    if (parameterless()) return entries[0];
    const shader::LtsdFetch f = shader::ltsdFetchUpper(float(g), entriesPerHalf, gMax);
    return shader::ltsdLerp(entries[size_t(f.i0)], entries[size_t(f.i1)], f.w);
}

shader::LtsdEntry LtsdTable::lower(double g) const {
    if (parameterless()) return entries[1];
    const shader::LtsdFetch f = shader::ltsdFetchLower(float(g), entriesPerHalf, gMax);
    return shader::ltsdLerp(entries[size_t(f.i0)], entries[size_t(f.i1)], f.w);
}

double LtsdTable::integral(const shader::SphericalPolygon& polygon, double g) const {
    return double(shader::ltsdPhaseIntegral(polygon, upper(g), lower(g), float(isotropicWeight()), 0.0f));
}

double LtsdTable::density(const glm::dvec3& w, double g) const {
    const double isotropic = isotropicWeight() / (4.0 * kPi);
    if (w.z >= 0.0) {
        const shader::LtsdEntry e = upper(g);
        return isotropic + double(e.amplitude) * double(shader::ltsdEval(e, glm::vec3(w)));
    }
    const shader::LtsdEntry e = lower(g);
    return isotropic +
           double(e.amplitude) * double(shader::ltsdEval(e, glm::vec3(float(w.x), float(w.y), float(-w.z))));
}

// ---------------------------------------------------------------------------------------------------------------------
// File format (docs/tables.md)

std::uint64_t ltsdTableChecksum(const std::vector<std::uint8_t>& fileBytes) {
    std::uint64_t hash = 0xcbf29ce484222325ull;
    for (std::size_t i = 0; i < fileBytes.size(); ++i) {
        const bool inChecksum = i >= kChecksumOffset && i < kChecksumOffset + 8;
        hash ^= inChecksum ? 0u : fileBytes[i];
        hash *= 0x100000001b3ull;
    }
    return hash;
}

void saveLtsdTable(const LtsdTable& table, const std::filesystem::path& file) {
    TY_CHECK(table.entriesPerHalf >= 1 && table.entries.size() == size_t(2 * table.entriesPerHalf),
             "an LTSD table needs 2n entries, n >= 1");
    TY_CHECK(table.phase.size() < 16, "phase type too long for the header");
    std::vector<std::uint8_t> bytes(kHeaderBytes + kEntryBytes * table.entries.size(), 0);
    std::memcpy(bytes.data(), kMagic, sizeof kMagic);
    put<std::uint32_t>(bytes, 8, LtsdTable::kVersion);
    put<std::uint32_t>(bytes, 12, std::uint32_t(table.entriesPerHalf));
    put<std::uint32_t>(bytes, 16, std::uint32_t(kEntryBytes));
    put<float>(bytes, 20, table.gMax);
    std::memcpy(bytes.data() + 24, table.phase.data(), table.phase.size());
    put<std::uint64_t>(bytes, 40, std::uint64_t(kEntryBytes * table.entries.size()));
    std::memcpy(bytes.data() + kHeaderBytes, table.entries.data(), kEntryBytes * table.entries.size());
    const std::uint64_t checksum = ltsdTableChecksum(bytes);
    put<std::uint64_t>(bytes, kChecksumOffset, checksum);
    writeAtomically(file, bytes.data(), bytes.size());

    nlohmann::json sidecar = table.provenance.is_object() ? table.provenance : nlohmann::json::object();
    sidecar["table"] = file.filename().string();
    sidecar["checksum"] = hex64(checksum);
    const std::string text = sidecar.dump(2) + "\n";
    writeAtomically(file.string() + ".json", text.data(), text.size());
}

LtsdTable loadLtsdTable(const std::filesystem::path& file, const std::string& expectedPhase) {
    const auto fail = [&](const std::string& field, const std::string& message) {
        return InputError(InputLocation{file.string(), 0, 0, field}, message);
    };
    const std::vector<std::uint8_t> bytes = table_file::readAll(file, "LTSD table");
    if (bytes.size() < kHeaderBytes || std::memcmp(bytes.data(), kMagic, sizeof kMagic) != 0)
        throw fail("header", "not an LTSD table (no TYLTSD magic, or shorter than its 64-byte header)");
    const auto version = get<std::uint32_t>(bytes, 8);
    if (version != LtsdTable::kVersion)
        throw fail("header.version", "version " + std::to_string(version) + "; this Tyndall reads version " +
                                         std::to_string(LtsdTable::kVersion) + " (re-fit with tyndall-fit-tables)");
    const auto n = get<std::uint32_t>(bytes, 12);
    const auto entryBytes = get<std::uint32_t>(bytes, 16);
    const auto payloadBytes = get<std::uint64_t>(bytes, 40);
    if (entryBytes != kEntryBytes) throw fail("header.entryBytes", "must be 48, got " + std::to_string(entryBytes));
    if (n < 1 || n > 65536) throw fail("header.entriesPerHalf", "must be in [1, 65536], got " + std::to_string(n));
    const std::uint64_t impliedPayload = std::uint64_t(2) * n * kEntryBytes;
    if (payloadBytes != impliedPayload)
        throw fail("header.payloadBytes", "says " + std::to_string(payloadBytes) + " bytes; 2 x " + std::to_string(n) +
                                              " entries (header.entriesPerHalf) of 48 bytes are " +
                                              std::to_string(impliedPayload));
    if (bytes.size() != kHeaderBytes + payloadBytes)
        throw fail("payload", "truncated or padded: the file has " + std::to_string(bytes.size()) +
                                  " bytes, its header implies " + std::to_string(kHeaderBytes + payloadBytes));
    const auto stored = get<std::uint64_t>(bytes, kChecksumOffset);
    if (stored != ltsdTableChecksum(bytes))
        throw fail("header.checksum", "checksum mismatch: the file is corrupt (stored " + hex64(stored) +
                                          ", computed " + hex64(ltsdTableChecksum(bytes)) + ")");

    LtsdTable table;
    table.path = file.string();
    table.entriesPerHalf = int(n);
    table.gMax = get<float>(bytes, 20);
    // The phase type: NUL-terminated text in bytes [24, 40), one of the types that have a table, and the one the
    // caller asked for (hg.ltsd must hold the hg table: the run time interpolates it by g).
    if (std::find(bytes.begin() + 24, bytes.begin() + 40, std::uint8_t(0)) == bytes.begin() + 40)
        throw fail("header.phase", "is not NUL-terminated within its 16 bytes");
    table.phase = reinterpret_cast<const char*>(bytes.data() + 24);
    const std::string shownPhase = "'" + table.phase.substr(0, 15) + "'";
    const bool knownPhase = table.phase == "hg" || table.phase == "rayleigh" || isMie(table.phase);
    if (!knownPhase)
        throw fail("header.phase",
                   shownPhase + " is not a phase type with an LTSD table (hg, rayleigh, hazy-mie, murky-mie)");
    if (!expectedPhase.empty() && table.phase != expectedPhase)
        throw fail("header.phase",
                   "the table fits " + shownPhase + ", but this file must hold the '" + expectedPhase + "' table");
    if ((table.phase == "hg") != (n >= 2))
        throw fail("header.entriesPerHalf",
                   table.phase == "hg"
                       ? "the hg table is parameterised by g: at least 2 entries per half, got 1"
                       : "a " + shownPhase + " table has no parameter: 1 entry per half, got " + std::to_string(n));
    if (n >= 2 && !(table.gMax > 0.0f && table.gMax <= 1.0f))
        throw fail("header.gMax", "must be in (0, 1], got " + std::to_string(table.gMax));
    if (n == 1 && table.gMax != 0.0f)
        throw fail("header.gMax", "must be 0 in a parameterless table (n = 1), got " + std::to_string(table.gMax));
    table.entries.resize(size_t(2) * n);
    std::memcpy(table.entries.data(), bytes.data() + kHeaderBytes, payloadBytes);
    for (size_t i = 0; i < table.entries.size(); ++i) {
        const shader::LtsdEntry& e = table.entries[i];
        const std::string field = "entries[" + std::to_string(i) + "]";
        for (float v : e.m)
            if (!std::isfinite(v)) throw fail(field + ".m", "a matrix element is not finite");
        const glm::mat3 m = shader::ltsdMatrix(e);
        const double det = double(glm::determinant(m));
        const double scale = double(glm::length(m[0]) * glm::length(m[1]) * glm::length(m[2]));
        if (!(det > 1e-9 * scale) || !(scale > 0.0))
            throw fail(field + ".m", "the matrix is singular or flips orientation (det " + std::to_string(det) + ")");
        if (!(e.amplitude >= 0.0f && e.amplitude <= 1.0f))
            throw fail(field + ".amplitude", "must be in [0, 1], got " + std::to_string(e.amplitude));
        const int expectedSource = i < n ? shader::kLtsdSourceClampedCosine : shader::kLtsdSourceInverseClampedCosine;
        if (n == 1 && e.source != shader::kLtsdSourceClampedCosine && e.source != shader::kLtsdSourceInverseClampedCosine)
            throw fail(field + ".source", "must be 0 or 1, got " + std::to_string(e.source));
        if (n >= 2 && e.source != expectedSource)
            throw fail(field + ".source", "must be " + std::to_string(expectedSource) + " in this half of the table");
        // Informative (the fetch computes the coordinate from the index), but a table whose entries say another g than
        // their place is not what the fitter wrote: its entries are out of order or damaged.
        const double g = n >= 2 ? table.entryG(int(i)) : 0.0;
        if (!(std::abs(double(e.g) - g) <= 1e-6))
            throw fail(field + ".g", "must be the entry's table coordinate " + formatNumber(g) +
                                         " (evenly spaced over [-gMax, 0] and [0, gMax]), got " + formatNumber(e.g));
    }

    const std::filesystem::path sidecar = file.string() + ".json";
    std::ifstream side(sidecar);
    if (side) {
        try {
            table.provenance = nlohmann::json::parse(side);
        } catch (const nlohmann::json::exception& e) {
            throw InputError(InputLocation{sidecar.string(), 0, 0, ""}, std::string("not valid JSON: ") + e.what());
        }
    }
    return table;
}

std::filesystem::path ltsdTablesDirectory(const std::string& overrideDir) {
    if (!overrideDir.empty()) return overrideDir;
    if (const char* env = std::getenv("TYNDALL_TABLES_DIR"); env && *env) return env;
    return resourceRoot() / "tables";
}

std::filesystem::path ltsdTablePath(const std::string& phaseType, const std::string& overrideDir) {
    return ltsdTablesDirectory(overrideDir) / (phaseType + ".ltsd");
}

std::vector<std::string> ltsdTablePhases(const std::string& overrideDir) {
    std::vector<std::string> phases;
    std::error_code ec;
    for (std::filesystem::directory_iterator it(ltsdTablesDirectory(overrideDir), ec), end; !ec && it != end;
         it.increment(ec))
        if (it->path().extension() == ".ltsd") phases.push_back(it->path().stem().string());
    std::sort(phases.begin(), phases.end());
    return phases;
}

// ---------------------------------------------------------------------------------------------------------------------
// Plot data

std::vector<LtsdPolarPoint> ltsdPolarCurve(const LtsdTable& table, double g, int points) {
    std::vector<LtsdPolarPoint> curve;
    curve.reserve(size_t(points));
    const LtsdPhase phase{table.phase, g};
    for (int i = 0; i < points; ++i) {
        const double psi = 2.0 * kPi * (double(i) + 0.5) / double(points);
        const glm::dvec3 w(std::sin(psi), 0.0, std::cos(psi));
        curve.push_back({psi, phase.eval(-w.z), table.density(w, g)});
    }
    return curve;
}

double ltsdTotalVariation(double g, int source, double m) {
    // x over [-30, 30] holds all but ~1e-13 of every density here; 600 panels of 8-point Gauss-Legendre.
    const double x0 = -30.0, x1 = 30.0;
    const int panels = 600;
    const double h = (x1 - x0) / panels, shift = std::log(m);
    double sum = 0.0;
    for (int p = 0; p < panels; ++p) {
        const double mid = x0 + (double(p) + 0.5) * h;
        for (int k = 0; k < 4; ++k) {
            for (double sgn : {-1.0, 1.0}) {
                const double x = mid + sgn * 0.5 * h * kGaussNodes[size_t(k)];
                const double diff = sourceDensityX(source, x - shift) - hgUpperDensityX(g, x);
                sum += 0.5 * h * kGaussWeights[size_t(k)] * std::abs(diff);
            }
        }
    }
    return sum;
}

double ltsdLobeTotalVariation(const std::string& type, double g, int side, int source, double m) {
    if (type == "hg") return ltsdTotalVariation(double(side) * g, source, m);
    const double upperShare = ltsdLobeCdf(type, g, 0.0);
    const double amplitude = side > 0 ? upperShare : 1.0 - upperShare;
    const double x0 = -30.0, x1 = 30.0;
    const int panels = 600;
    const double h = (x1 - x0) / panels, shift = std::log(m);
    double sum = 0.0;
    for (int p = 0; p < panels; ++p) {
        const double mid = x0 + (double(p) + 0.5) * h;
        for (int k = 0; k < 4; ++k) {
            for (double sgn : {-1.0, 1.0}) {
                const double x = mid + sgn * 0.5 * h * kGaussNodes[size_t(k)];
                const double diff = sourceDensityX(source, x - shift) - lobeDensityX(type, g, side, amplitude, x);
                sum += 0.5 * h * kGaussWeights[size_t(k)] * std::abs(diff);
            }
        }
    }
    return sum;
}

LtsdFitError ltsdFitErrorAt(const LtsdTable& table, double g) {
    g = table.parameterless() ? 0.0 : std::clamp(g, -double(table.gMax), double(table.gMax));
    const shader::LtsdEntry u = table.upper(g), l = table.lower(g);
    LtsdFitError e;
    e.g = g;
    e.tvUpper = ltsdLobeTotalVariation(table.phase, g, 1, u.source, double(u.m[0]) / double(u.m[8]));
    e.tvLower = ltsdLobeTotalVariation(table.phase, g, -1, l.source, double(l.m[0]) / double(l.m[8]));
    e.bound = 0.5 * (double(u.amplitude) * e.tvUpper + double(l.amplitude) * e.tvLower);
    return e;
}

std::vector<LtsdFitError> ltsdFitErrorCurve(const LtsdTable& table, int points) {
    std::vector<LtsdFitError> curve;
    if (table.parameterless()) return {ltsdFitErrorAt(table, 0.0)};
    for (int i = 0; i < points; ++i)
        curve.push_back(ltsdFitErrorAt(table, -double(table.gMax) + 2.0 * double(table.gMax) * double(i) / double(points - 1)));
    return curve;
}

}  // namespace tyndall

namespace tyndall {

namespace {

// Gauss-Kronrod 7/15 on [-1, 1]: Kronrod nodes (positive half, the last is 0) and weights, and the Gauss weights of
// the nodes with odd index.
constexpr std::array<double, 8> kKronrodNodes = {0.991455371120812639, 0.949107912342758525, 0.864864423359769073,
                                                 0.741531185599394440, 0.586087235467691130, 0.405845151377397167,
                                                 0.207784955007898468, 0.0};
constexpr std::array<double, 8> kKronrodWeights = {0.022935322010529225, 0.063092092629978553, 0.104790010322250184,
                                                   0.140653259715525919, 0.169004726639267903, 0.190350578064785410,
                                                   0.204432940075298892, 0.209482141084727828};
constexpr std::array<double, 4> kGauss7Weights = {0.129484966168869693, 0.279705391489276668, 0.381830050505118945,
                                                  0.417959183673469388};

template <typename F>
double kronrod(const F& f, double a, double b, double tolerance, double relativeTolerance, int depth) {
    const double centre = 0.5 * (a + b), half = 0.5 * (b - a);
    double kronrodSum = kKronrodWeights[7] * f(centre), gaussSum = kGauss7Weights[3] * f(centre);
    for (size_t i = 0; i < 7; ++i) {
        const double dx = half * kKronrodNodes[i];
        const double pair = f(centre - dx) + f(centre + dx);
        kronrodSum += kKronrodWeights[i] * pair;
        if (i % 2 == 1) gaussSum += kGauss7Weights[i / 2] * pair;
    }
    kronrodSum *= half;
    gaussSum *= half;
    const double error = std::abs(kronrodSum - gaussSum);
    if (depth >= 24 || error <= std::max(tolerance, relativeTolerance * std::abs(kronrodSum))) return kronrodSum;
    return kronrod(f, a, centre, 0.5 * tolerance, relativeTolerance, depth + 1) +
           kronrod(f, centre, b, 0.5 * tolerance, relativeTolerance, depth + 1);
}

}  // namespace

// The boundary form (docs/tables.md, "The exact integral over a polygon"). In coordinates (phi, mu) about the z axis,
// d omega = d mu d phi, so with C(mu) = cdf(mu) / (2 pi) the integral over a region between two curves in mu is an
// integral of C along its boundary (Green's theorem): I = |oint C(mu) d phi| when the polygon holds no pole,
// oint C d phi (traversed with phi increasing) when it holds mu = -1 (+z), and 1 - oint C d phi when it holds
// mu = +1 (-z). Along an edge C(mu) d phi is integrated as c0 Delta phi + int (C(mu) - c0) phi'(t) dt, with c0 the
// value at the pole nearer the edge, so that the integrand stays bounded where an edge passes near that pole (phi'
// grows as 1 / r^2 there, C - c0 falls as r^2).
double ltsdPhasePolygonIntegral(const LtsdPhase& phase, const std::vector<glm::dvec3>& vertices) {
    TY_CHECK(vertices.size() >= 3, "a polygon has at least 3 vertices");
    glm::dvec3 centre(0.0);
    for (const glm::dvec3& v : vertices)
        centre += glm::normalize(v);
    centre = glm::normalize(centre);
    // A vertex on the z axis has no phi: moved by 1e-9 rad towards the centre (an area change of order 1e-18 sr).
    std::vector<glm::dvec3> polygon;
    for (const glm::dvec3& v : vertices) {
        glm::dvec3 w = glm::normalize(v);
        if (w.x * w.x + w.y * w.y < 1e-24) w = glm::normalize(w + 1e-9 * (centre - w));
        polygon.push_back(w);
    }
    const auto C = [&](double mu) { return phase.cdf(std::clamp(mu, -1.0, 1.0)) / (2.0 * kPi); };
    double boundary = 0.0, winding = 0.0;
    for (size_t i = 0; i < polygon.size(); ++i) {
        const glm::dvec3 a = polygon[i], b = polygon[(i + 1) % polygon.size()];
        const double deltaPhi = std::atan2(a.x * b.y - a.y * b.x, a.x * b.x + a.y * b.y);
        winding += deltaPhi;
        const double angle = std::acos(std::clamp(glm::dot(a, b), -1.0, 1.0));
        if (angle == 0.0) continue;
        const glm::dvec3 u = glm::normalize(b - glm::dot(a, b) * a);  // a cos t + u sin t runs from a to b
        const double c0 = (a.z + b.z) < 0.0 ? C(1.0) : C(-1.0);       // mu = -z: the pole the edge is nearer
        const auto integrand = [&](double t) {
            const glm::dvec3 w = a * std::cos(t) + u * std::sin(t), dw = -a * std::sin(t) + u * std::cos(t);
            const double r2 = w.x * w.x + w.y * w.y;
            if (r2 == 0.0) return 0.0;
            return (C(-w.z) - c0) * (w.x * dw.y - w.y * dw.x) / r2;
        };
        boundary += c0 * deltaPhi + kronrod(integrand, 0.0, angle, 1e-14, 1e-13, 0);
    }
    if (std::abs(winding) < kPi) return std::abs(boundary);
    const double increasing = winding > 0.0 ? boundary : -boundary;
    return centre.z > 0.0 ? increasing : 1.0 - increasing;
}

double integrateOverSphericalPolygon(const std::vector<glm::dvec3>& vertices, const glm::dvec3& centre,
                                     const std::function<double(const glm::dvec3&)>& f, double tolerance,
                                     double relativeTolerance) {
    // On the planar triangle q(s, v) = c + s (a - c) + (1 - s) v (b - c), s, v in [0, 1], the solid angle element is
    // ((a - c) x (b - c)) . c (1 - s) / |q|^3 ds dv (the central projection of a planar area element), signed by the
    // triangle's orientation, so that the fan is exact for any centre inside the polygon's hemisphere.
    const glm::dvec3 c = glm::normalize(centre);
    double sum = 0.0;
    const double edges = double(vertices.size());
    for (size_t i = 0; i < vertices.size(); ++i) {
        const glm::dvec3 a = glm::normalize(vertices[i]);
        const glm::dvec3 b = glm::normalize(vertices[(i + 1) % vertices.size()]);
        const double k = glm::dot(glm::cross(a - c, b - c), c);  // signed: a centre outside still sums correctly
        if (k == 0.0) continue;
        const auto inner = [&](double s) {
            const auto integrand = [&](double v) {
                const glm::dvec3 q = c + s * (a - c) + (1.0 - s) * v * (b - c);
                const double l = glm::length(q);
                return f(q / l) * k * (1.0 - s) / (l * l * l);
            };
            return kronrod(integrand, 0.0, 1.0, tolerance / edges, relativeTolerance, 0);
        };
        sum += kronrod(inner, 0.0, 1.0, tolerance / edges, relativeTolerance, 0);
    }
    return std::abs(sum);
}

}  // namespace tyndall
