// LTSD tables of phase functions (LTSD paper (000), Sec. 5 and 7): the fitted entries, their file format (versioned,
// checksummed, docs/tables.md), where installed tables are found, the run-time fetch of Eq. 24 and S of Eq. 21 on the
// CPU, and the data behind the studio's plots (polar curves of the phase function against its fit, fit error
// against g). The fitter itself is in tables/ (tyndall-fit-tables).
#pragma once

#include "shared/ltsd.h"

#include <nlohmann/json.hpp>

#include <cstdint>
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

namespace tyndall {

// A phase function as the LTSD tables see it, evaluated in double: the project-format types hg, isotropic, mix,
// rayleigh, eddington, hazy-mie and murky-mie (legendre has no table: its series is the user's).
struct LtsdPhase {
    std::string type = "hg";  // project-format phase type
    double g = 0.0;           // hg and mix: asymmetry, in (-1, 1)
    double a = 1.0;           // mix: weight of the HG lobe, in [0, 1]
    double b = 0.0;           // eddington: (1 + b mu) / (4 pi), b in [-1, 1]

    // p(mu) per sr, project convention (mu = 1: forward scattering).
    double eval(double mu) const;
    // Its CDF in mu: 2 pi times the integral of p over [-1, mu], in closed form (cdf(1) = 1).
    double cdf(double mu) const;
};

// The exact integral of the phase function over a spherical polygon in the LTSD frame (mu = -z): the boundary form of
// docs/tables.md ("The exact integral over a polygon"), one smooth 1-D integral of the closed-form CDF per edge, plus
// the pole's term when the polygon holds one. Its work is bounded for every g: where the phase function is a spike
// (g = 0.9999999) that a 2-D quadrature chases for minutes, the CDF is a step the edge integrals resolve in a few
// hundred evaluations. `vertices`: a convex polygon inside a hemisphere, any order.
double ltsdPhasePolygonIntegral(const LtsdPhase& phase, const std::vector<glm::dvec3>& vertices);

// S by the boundary form (shaders/shared/ltsd_boundary.h, tables eval's sMethods.accurate): the same integral in float
// with 3 Gauss nodes per edge, no table (docs/tables.md, "S by the boundary form"). Every type but legendre.
double ltsdAccuratePhaseIntegral(const LtsdPhase& phase, const shader::SphericalPolygon& polygon);

// What the boundary form needs for one phase function (the arguments of shared/ltsd_boundary.h's
// ltsdAccuratePhaseIntegral): its lobe (kLtsdLobe*; none for isotropic and eddington, which are exact), the lobe's HG
// asymmetry and weight, and the exact part's weights. Throws InputError for a type without an LTSD form (legendre).
struct LtsdBoundaryTerms {
    int lobe = 0;  // shader::kLtsdLobeNone
    float g = 0.0f;
    float lobeWeight = 0.0f;
    float isotropic = 0.0f;  // weight of 1 / (4 pi)
    float linear = 0.0f;     // weight of mu / (4 pi)
};
LtsdBoundaryTerms ltsdBoundaryTerms(const LtsdPhase& phase);

// Henyey-Greenstein's integral over the upper hemisphere of the LTSD frame (omega_o = +z, mu = -z), i.e. over
// mu in [-1, 0]: a_u(g) = (1 - g) / (sqrt(1 + g^2) (1 + g + sqrt(1 + g^2))), exact and stable for every g in [-1, 1].
// a_l(g) = a_u(-g), and a_u + a_l = 1.
double hgUpperAmplitude(double g);

// ---------------------------------------------------------------------------------------------------------------------
// Other phase functions (docs/tables.md, "Other phase functions"): a phase function is split into an exact part
// (isotropic + linear mu) / (4 pi), integrated in closed form over any polygon, and a lobe that a table's LTSDs fit:
//   hg: the lobe is HG (weight 1);  mix: (1 - a) isotropic + a HG (the HG table);  isotropic, eddington: exact only;
//   rayleigh: 3/4 isotropic + 1/4 of the lobe 3 mu^2 / (4 pi);  hazy-mie, murky-mie: 1/2 isotropic + 1/2 of the lobe
//   (n + 1) ((1 + mu) / 2)^n / (4 pi), n = 8 or 32.

// The table a phase type needs ("hg" for hg and mix, the type itself for rayleigh and the Mie presets), or "" when it
// is exact without one (isotropic, eddington). Throws InputError for a type that has no LTSD form (legendre).
std::string ltsdTableFor(const std::string& phaseType);

// The lobe that a table fits, normalised over the sphere (per sr), at mu; `g` is used by hg only.
double ltsdLobeEval(const std::string& tableType, double g, double mu);
// Its integral over mu' in [-1, mu] (times 2 pi): the lobe's CDF in mu.
double ltsdLobeCdf(const std::string& tableType, double g, double mu);
// The lobe's share of its phase function (hg 1, rayleigh 1/4, the Mie presets 1/2).
double ltsdLobeWeight(const std::string& tableType);

struct LtsdTable {
    static constexpr std::uint32_t kVersion = 1;

    std::string phase = "hg";  // what the table fits (a project-format phase type)
    int entriesPerHalf = 0;    // n: entries [0, n) are T_1 over g in [-gMax, 0], [n, 2n) are T_2 over [0, gMax]
    float gMax = 0.0f;         // |g| beyond gMax is clamped to gMax
    std::vector<shader::LtsdEntry> entries;  // 2n
    nlohmann::json provenance;                // from the sidecar (null when it is missing)
    std::string path;                         // the file it was loaded from

    // The table coordinate of entry i.
    double entryG(int i) const;

    // Eq. 24: M_u with a_u, and the T of M_l = diag(1, 1, -1) T with a_l, interpolated.
    shader::LtsdEntry upper(double g) const;
    shader::LtsdEntry lower(double g) const;

    // A parameterless table (rayleigh, the Mie presets) has n = 1: entry 0 is M_u, entry 1 the T of M_l; g is ignored.
    bool parameterless() const { return entriesPerHalf == 1; }

    // The weight of the exact isotropic part of the table's phase function: 1 - a_u - a_l of a parameterless table
    // (its amplitudes carry the lobe's weight), 0 for HG.
    double isotropicWeight() const;

    // Eq. 21 (with the isotropic part of a parameterless table): the LTSD approximation of the phase function's
    // integral over the polygon (frame: omega_o = +z).
    double integral(const shader::SphericalPolygon& polygon, double g) const;

    // The fitted density per sr in direction w (unit, frame omega_o = +z): a_u D_u or a_l D_l by hemisphere.
    double density(const glm::dvec3& w, double g) const;
};

// The measured quality of each phase type's LTSD form: the largest and the mean absolute error of its integral over
// the 24 random polygons of tables/test against adaptive quadrature (the worst over the tested parameters), measured
// 2026-12-03 (docs/tables.md; the tables test fails when a measurement leaves these by more than 5 %). The LTSD
// technique accepts a phase type whose errors are within kLtsdAccepted*: the shipped HG table's worst (g = 0.8 and
// 0.95), the accuracy of the paper's method itself.
struct LtsdPhaseQuality {
    const char* type;
    double maxAbs;
    double meanAbs;
};
inline constexpr double kLtsdAcceptedMaxAbs = 5.0e-2;
inline constexpr double kLtsdAcceptedMeanAbs = 6.0e-3;
inline constexpr LtsdPhaseQuality kLtsdPhaseQuality[] = {
    {"hg", 4.916e-02, 5.919e-03},       {"mix", 4.916e-02, 5.919e-03},       {"isotropic", 1e-6, 1e-7},
    {"eddington", 1e-6, 1e-7},          {"rayleigh", 1.616e-03, 3.499e-04},  {"hazy-mie", 6.758e-03, 7.363e-04},
    {"murky-mie", 3.563e-02, 3.517e-03},
};

// Why the LTSD technique cannot render a phase type ("" when it can): no LTSD form (legendre), or a measured error
// above the threshold (naming both).
std::string ltsdPhaseRefusal(const std::string& phaseType);

// What the run time needs for one phase function: the two (interpolated) entries with the lobe's amplitudes and the
// weights of the exact part, for ltsdPhaseIntegral of shared/ltsd.h.
struct LtsdPhaseTerms {
    shader::LtsdEntry upper{};
    shader::LtsdEntry lower{};
    float isotropic = 0.0f;  // weight of 1 / (4 pi)
    float linear = 0.0f;     // weight of mu / (4 pi)
};

// The terms of `phase`; `table` is the table of ltsdTableFor(phase.type) (unused, may be null, when that is "").
LtsdPhaseTerms ltsdPhaseTerms(const LtsdPhase& phase, const LtsdTable* table);

// ltsdPhaseIntegral of shared/ltsd.h with these terms, in the frame omega_o = +z.
double ltsdPhaseIntegral(const LtsdPhaseTerms& terms, const shader::SphericalPolygon& polygon);

// Reads a table; every problem (missing, truncated, another version, bad checksum, a header phase type without a
// table or other than `expectedPhase` when that is given, non-finite or singular matrices, amplitudes outside [0, 1],
// entries whose g is not their table coordinate) is an InputError naming the file and the field. The sidecar
// `<file>.json` holds the provenance.
LtsdTable loadLtsdTable(const std::filesystem::path& file, const std::string& expectedPhase = "");

// Writes the table and its sidecar (provenance as given, plus the payload checksum), each atomically.
void saveLtsdTable(const LtsdTable& table, const std::filesystem::path& file);

// The checksum stored in a table file: FNV-1a (64 bit) of the whole file with the checksum field zeroed.
std::uint64_t ltsdTableChecksum(const std::vector<std::uint8_t>& fileBytes);

// Where tables are found: `overrideDir` if not empty, else $TYNDALL_TABLES_DIR, else resourceRoot() / "tables"
// (tyndall/core/resources.h: $TYNDALL_ROOT, the installed or bundled layout, or the source tree).
std::filesystem::path ltsdTablesDirectory(const std::string& overrideDir = "");

// The table file for a phase type, e.g. "hg" -> <dir>/hg.ltsd.
std::filesystem::path ltsdTablePath(const std::string& phaseType, const std::string& overrideDir = "");

// The phase types that have a table file in the tables directory (<type>.ltsd), sorted; for messages such as "no LTSD
// table for rayleigh; tables exist for: hg". Does not load or check them.
std::vector<std::string> ltsdTablePhases(const std::string& overrideDir = "");

// ---------------------------------------------------------------------------------------------------------------------
// Plot data for the studio and the CLI

// The phase function against its fit in the plane y = 0 through omega_o (the LTSD paper's Fig. 12): direction
// w = (sin psi, 0, cos psi) for psi over [0, 2 pi), so psi = 0 is omega_o and psi = pi the forward direction.
struct LtsdPolarPoint {
    double psi;     // radians
    double phase;   // p(mu) per sr, mu = -cos psi
    double fitted;  // the LTSD's density per sr (discontinuous at the horizon, psi = pi / 2 and 3 pi / 2)
};
std::vector<LtsdPolarPoint> ltsdPolarCurve(const LtsdTable& table, double g, int points);

// How well each hemisphere is fitted at g: the total-variation distance int |D_fit - D| over the hemisphere between
// the normalised fitted and target distributions (in [0, 2]); any region's integral of the phase function is then off
// by at most (a_u tv_u + a_l tv_l) / 2.
struct LtsdFitError {
    double g;
    double tvUpper;
    double tvLower;
    double bound;  // (a_u tv_u + a_l tv_l) / 2
};
std::vector<LtsdFitError> ltsdFitErrorCurve(const LtsdTable& table, int points);

// The same at one g (clamped to the table's range as the fetch clamps it): the error the studio's caption quotes.
LtsdFitError ltsdFitErrorAt(const LtsdTable& table, double g);

// The total-variation distance between HG's hemisphere at g (upper: mu in [-1, 0]) and an entry's fitted distribution
// of the same hemisphere, for entries of the form M = diag(m, m, 1) (what the fitter produces). Deterministic
// quadrature in x = ln tan(theta), where the fit is a shift of the source: see docs/tables.md.
double ltsdTotalVariation(double g, int source, double m);

// The same for the lobe of a table type (ltsdLobeEval) on one hemisphere: side +1 the upper (mu in [-1, 0]), -1 the
// lower mirrored to the upper one (mu = z). For "hg" it is ltsdTotalVariation(side * g, ...).
double ltsdLobeTotalVariation(const std::string& tableType, double g, int side, int source, double m);

// ---------------------------------------------------------------------------------------------------------------------
// Reference integrals

// The integral of f over a spherical polygon (the cone through `vertices`, a simple polygon inside a hemisphere that
// also holds `centre`, e.g. its normalised mean direction), by adaptive Gauss-Kronrod (7/15) quadrature, nested in two dimensions over
// the fan of planar triangles (centre, v_i, v_i+1) projected onto the sphere; to about `tolerance` absolute or
// `relativeTolerance` relative. Independent of the edge integrals of shared/ltsd.h, which the tests check against it.
double integrateOverSphericalPolygon(const std::vector<glm::dvec3>& vertices, const glm::dvec3& centre,
                                     const std::function<double(const glm::dvec3&)>& f, double tolerance = 1e-10,
                                     double relativeTolerance = 1e-8);

}  // namespace tyndall
