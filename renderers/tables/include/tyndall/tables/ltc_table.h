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

    int dimensions = 2;                       // 2: isotropic (ggx.ltc); 4: anisotropic (ggx-aniso.ltc)
    std::array<int, 4> sizes = {1, 1, 1, 1};  // entries per dimension, fastest first: isotropic (x, alpha),
                                              // anisotropic (theta, phi, alpha, ratio)
    float alphaMin = 0.0f;                    // alpha's grid is uniform over [alphaMin, 1]
    float ratioMin = 0.0f;                    // anisotropic: r's grid is uniform over [ratioMin, 1]; isotropic: 0
    std::vector<shader::LtcEntry> entries;    // sizes[0] * sizes[1] * ...
    nlohmann::json provenance;                // from the sidecar (null when it is missing)
    std::string path;                         // the file it was loaded from

    bool isotropicTable() const { return dimensions == 2; }
    int xCount() const { return sizes[0]; }  // isotropic
    int alphaCount() const { return isotropicTable() ? sizes[1] : sizes[2]; }
    int thetaCount() const { return sizes[0]; }  // anisotropic
    int phiCount() const { return sizes[1]; }
    int ratioCount() const { return sizes[3]; }

    // The grid: x = sqrt(1 - cos theta_o) uniform over [0, 1] (cos theta_o fitted as max(1 - x^2, kLtcMinCosTheta)),
    // alpha uniform over [alphaMin, 1]; entry (ix, ia) is at index ia * xCount() + ix.
    static double gridAlpha(int ia, int alphaCount, double alphaMin);
    static double gridCosTheta(int ix, int xCount);
    double entryAlpha(int i) const { return gridAlpha(i / xCount(), alphaCount(), alphaMin); }
    double entryCosTheta(int i) const { return gridCosTheta(i % xCount(), xCount()); }

    // The anisotropic grid (shared/ltc.h): theta_o and phi_o uniform over [0, pi / 2] (theta_o fitted with
    // cos theta_o >= kLtcMinCosTheta), r = min / max roughness uniform over [ratioMin, 1] (fitted with the smaller
    // roughness max(r alpha, alphaMin)); entry (it, ip, ia, ir) at ((ir * nAlpha + ia) * nPhi + ip) * nTheta + it.
    static double gridTheta(int it, int thetaCount);
    static double gridPhi(int ip, int phiCount);
    static double gridRatio(int ir, int ratioCount, double ratioMin);

    // The bilinearly interpolated entry (shared/ltc.h's fetch) at alpha and cos theta_o (both clamped to the grid).
    shader::LtcEntry isotropic(double alpha, double cosTheta) const;

    // The quadrilinearly interpolated canonical entry for (alphaX, alphaY) seen from wo (shading frame), and F S, the
    // map of the polygon into its frame (shared/ltc.h's fetch).
    shader::LtcEntry anisotropic(double alphaX, double alphaY, const glm::dvec3& wo, glm::mat3& toCanonical) const;

    // The LTC approximation of int_P f(wo, wi) cos theta_i d wi of GGX with Schlick's F0 (per channel; F0 = 1 turns
    // Fresnel off), for a polygon in the shading frame (normal +z, x the tangent) and wo unit in that frame. Isotropic
    // table (alphaX = alphaY): the polygon is rotated into the entry's frame (omega_o in the xz-plane); anisotropic:
    // mapped by F S into the canonical frame; then clipped to the horizon and transformed by M^-1.
    glm::dvec3 integral(const shader::SphericalPolygon& polygon, const glm::dvec3& wo, double alphaX, double alphaY,
                        const glm::dvec3& f0) const;
};

// Reads a table; every problem (missing, truncated or padded, another version, bad checksum, an unknown layout,
// non-finite, singular or orientation-flipping matrices, moments outside their ranges) is an InputError naming the
// file. The sidecar `<file>.json` holds the provenance.
LtcTable loadLtcTable(const std::filesystem::path& file);

// Writes the table and its sidecar (provenance as given, plus the checksum), each atomically.
void saveLtcTable(const LtcTable& table, const std::filesystem::path& file);

// The table file: <ltsdTablesDirectory(overrideDir)>/<name>.ltc, e.g. ggx.ltc or ggx-aniso.ltc.
std::filesystem::path ltcTablePath(const std::string& name = "ggx", const std::string& overrideDir = "");

}  // namespace tyndall
