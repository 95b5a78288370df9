// LTC GGX tables (#17 item 4): linearly transformed cosines fitted to GGX with height-correlated Smith (shared/bsdf.h)
// times the cosine, for the LTSD technique's surfaces. The fitted entries, their file format (versioned, checksummed,
// the same machinery as the LTSD tables; docs/tables.md, "LTC GGX tables"), the CPU fetch and polygon integral (the
// shared code of shared/ltc.h), and the GGX lobe in double that the fitter and the tests integrate. The fitter is in
// tables/ (tyndall-fit-tables --ltc).
#pragma once

#include "shared/ltc.h"

#include <nlohmann/json.hpp>

#include <array>
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

namespace tyndall {

// f(wo, wi) max(wi.z, 0) of GGX with height-correlated Smith and F = 1 (shared/bsdf.h's bsdfEval with f0 = 1, in
// double), per sr; wo and wi unit, in the shading frame (normal +z); 0 when either is below the horizon.
double ggxCosineLobe(const glm::dvec3& wo, const glm::dvec3& wi, double alphaX, double alphaY);

struct LtcTable {
    static constexpr std::uint32_t kVersion = 1;

    int dimensions = 2;                       // 2: the isotropic table (the only kind so far)
    std::array<int, 4> sizes = {1, 1, 1, 1};  // entries per dimension, fastest first: isotropic (x, alpha)
    float alphaMin = 0.0f;                    // alpha's grid is uniform over [alphaMin, 1]
    std::vector<shader::LtcEntry> entries;    // sizes[0] * sizes[1] * ...
    nlohmann::json provenance;                // from the sidecar (null when it is missing)
    std::string path;                         // the file it was loaded from

    int xCount() const { return sizes[0]; }
    int alphaCount() const { return sizes[1]; }

    // The grid: x = sqrt(1 - cos theta_o) uniform over [0, 1] (cos theta_o fitted as max(1 - x^2, kLtcMinCosTheta)),
    // alpha uniform over [alphaMin, 1]; entry (ix, ia) is at index ia * xCount() + ix.
    static double gridAlpha(int ia, int alphaCount, double alphaMin);
    static double gridCosTheta(int ix, int xCount);
    double entryAlpha(int i) const { return gridAlpha(i / xCount(), alphaCount(), alphaMin); }
    double entryCosTheta(int i) const { return gridCosTheta(i % xCount(), xCount()); }

    // The bilinearly interpolated entry (shared/ltc.h's fetch) at alpha and cos theta_o (both clamped to the grid).
    shader::LtcEntry isotropic(double alpha, double cosTheta) const;

    // The LTC approximation of int_P f(wo, wi) cos theta_i d wi of isotropic GGX with Schlick's F0 (per channel; F0 = 1
    // turns Fresnel off), for a polygon in the shading frame (normal +z) and wo unit in that frame: the polygon is
    // rotated into the entry's frame (omega_o in the xz-plane), clipped to the horizon, transformed by M^-1.
    glm::dvec3 integral(const shader::SphericalPolygon& polygon, const glm::dvec3& wo, double alpha,
                        const glm::dvec3& f0) const;
};

// Reads a table; every problem (missing, truncated or padded, another version, bad checksum, an unknown layout,
// non-finite, singular or orientation-flipping matrices, moments outside their ranges) is an InputError naming the
// file. The sidecar `<file>.json` holds the provenance.
LtcTable loadLtcTable(const std::filesystem::path& file);

// Writes the table and its sidecar (provenance as given, plus the checksum), each atomically.
void saveLtcTable(const LtcTable& table, const std::filesystem::path& file);

// The table file: <ltsdTablesDirectory(overrideDir)>/<name>.ltc, e.g. ggx.ltc.
std::filesystem::path ltcTablePath(const std::string& name = "ggx", const std::string& overrideDir = "");

}  // namespace tyndall
