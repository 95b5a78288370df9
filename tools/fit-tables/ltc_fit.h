// The LTC GGX fitter (tyndall-fit-tables --ltc): fits the isotropic table of linearly transformed cosines to GGX with
// height-correlated Smith times the cosine (F = 1), the clamped cosine as the source, deterministically
// (docs/tables.md, "LTC GGX tables").
//
// Per entry (alpha, theta_o), with omega_o = (sin theta_o, 0, cos theta_o):
//  - the moments norm = int f cos and fresnel = int f cos (1 - omega_i . h)^5 by quasi-Monte Carlo over GGX's visible
//    normals (the integrand is G2 / G1, smooth and bounded);
//  - M minimising the total-variation distance int |p - q| over the sphere between the normalised lobe p (0 below the
//    horizon) and the LTC q of M, estimated with fixed quasi-random samples of both (balance heuristic): it bounds the
//    error of every polygon integral, |int_P p - int_P q| <= tv / 2.
// The lobe is symmetric about the xz-plane, so M = [[a, 0, b], [0, c, 0], [d, 0, e]] (up to scale): four parameters.
// At normal incidence the lobe is rotationally symmetric, M = diag(m, m, 1), found by a scan and golden-section search;
// every other entry is fitted by Nelder-Mead over M = M_prev (I + P), P with entries at (0, 0), (0, 2), (1, 1), (2, 0),
// started from the stored (float) entry at the previous theta of the same alpha. An entry therefore depends only on the
// stored entry before it, so any entry can be re-fitted from a shipped table and compared bit for bit; the rows (one
// per alpha) are independent, and threads only decide which thread fits which row.
#pragma once

#include "tyndall/tables/ltc_table.h"

#include <functional>
#include <vector>

namespace tyndall::tables {

struct LtcFitSettings {
    bool anisotropic = false;  // the isotropic table (x, alpha) or the anisotropic one (theta, phi, alpha, ratio)
    int xCount = 64;           // isotropic: entries over x = sqrt(1 - cos theta_o), uniform over [0, 1]
    int alphaCount = 64;       // entries over alpha, uniform over [alphaMin, 1] (anisotropic: 8)
    int thetaCount = 8;        // anisotropic: entries over theta_o, phi_o (uniform over [0, pi / 2]) and r = min / max
    int phiCount = 8;          // roughness (uniform over [ratioMin, 1])
    int ratioCount = 8;
    float ratioMin = 0.1f;      // anisotropic: r's smallest grid value (below it lobes are thin arcs, docs/tables.md)
    float alphaMin = 1e-3f;     // the project's smallest roughness
    int samples = 1024;         // per strategy (visible normals, the LTC) of the loss's estimate
    int momentSamples = 16384;  // visible-normal samples of norm, fresnel and the stored error
    int threads = 0;            // 0: all hardware threads
};

nlohmann::json ltcSettingsToJson(const LtcFitSettings& settings);
// The settings recorded in a table's provenance (as written by ltcSettingsToJson); absent fields keep their values.
void ltcSettingsFromJson(const nlohmann::json& json, LtcFitSettings& settings);

struct GgxMoments {
    double norm;     // int f cos d omega_i (F = 1)
    double fresnel;  // int f cos (1 - omega_i . h)^5 d omega_i
};
GgxMoments ggxMoments(const glm::dvec3& wo, double alphaX, double alphaY, int samples);

// The loss: an estimate of the total-variation distance int |p - q| (over the sphere, in [0, 2]) between GGX's
// normalised lobe p for omega_o and the LTC q of M, with `samples` fixed quasi-random samples from each of GGX's
// visible normals (reflected) and the LTC, combined by the balance heuristic.
class LtcLoss {
public:
    LtcLoss(const glm::dvec3& wo, double alphaX, double alphaY, double norm, int samples);
    double operator()(const glm::dmat3& m) const;
    // The normalised lobe's mean direction (estimated with the visible-normal samples), unit.
    glm::dvec3 targetMean() const;

private:
    // p (normalised) and the visible-normal density of direction w.
    void densities(const glm::dvec3& w, double& p, double& pv) const;

    glm::dvec3 wo_;
    double ax_, ay_, norm_, g1o_, lambdaO_;
    std::vector<glm::dvec3> vndfDirections_;
    std::vector<double> vndfP_, vndfPdf_;
    std::vector<glm::dvec3> cosineSamples_;
};

// The anisotropic table (002), an extension of the above per entry (it, ip, ia, ir) with omega_o at (theta_o, phi_o)
// and the roughnesses (alpha, max(r alpha, alphaMin)):
//  - theta_o = 0: the lobe is symmetric under both flips, M = diag(a, c, 1), found by Nelder-Mead over (a, c) from the
//    isotropic one-parameter fits at either roughness (at r = 1 these fits themselves, a = c); every phi copies the
//    entry at phi = 0 (002 Eq. 16);
//  - phi_o = 0 (pi / 2): symmetric about the xz- (yz-) plane, the four-parameter form with the other entries exactly
//    zero (002 Eq. 16);
//  - otherwise all of M: Nelder-Mead over M_0 (I + P) with seven parameters (P(2, 2) = 0 fixes the scale,
//    P(0, 1) = P(1, 0) the rotation about z that leaves an LTC unchanged), then aligned (002 Sec. 5.2) by the rotation
//    about z that moves the cosine's samples least.
//  M_0 is the best (smallest loss) of the entries at the previous theta, at normal incidence and, for the general
//  form, at the previous phi and at phi = 0, each first rotated so that its LTC's mean direction is the lobe's: the
//  lobes of neighbouring entries need not overlap at low roughness, where the loss is flat (002's "null gradients");
//  - r = 1 (isotropic GGX): M(phi) = R_z(phi) M(0) R_z(-phi) from the fitted phi = 0 entry, exactly the rotated lobe,
//    so that the swap symmetry (002 Eq. 14) is exact where alphaX = alphaY (beyond 002's post-processing).
// Each row (ia, ir) is fitted in index order (theta fastest, then phi): an entry depends only on stored entries before
// it in its row, given by `stored(index)`.
shader::LtcEntry fitLtcAnisotropicEntry(int index, const LtcFitSettings& settings,
                                        const std::function<const shader::LtcEntry&(int)>& stored);

// The alignment of 002 (Sec. 5.2, Eq. 12): M R_z(psi) F (F a flip of x and/or y) represents the same LTC for every psi
// and F; the aligned matrix is the one that moves the clamped cosine's samples least, minimising the mean of
// |M' s / |M' s| - s|^2 over fixed samples s. Found by a scan over psi (0.5 degree steps) and golden-section search,
// for each of the four flips.
struct LtcAlignment {
    double psi;  // radians
    bool flipX, flipY;
    glm::dmat3 aligned;  // M R_z(psi) F
    double cost;         // the mean squared distance at the aligned matrix
};
// `flips` false: rotations only (which include flipping both x and y), keeping det M's sign; `samples` cosine samples.
LtcAlignment ltcAlignment(const glm::dmat3& m, bool flips = true, int samples = 1024, double step = 0.5);

// The stored entry at index ia * xCount + ix (docs/tables.md): the fitted M (third column of unit length), the moments
// and the loss at M with momentSamples samples. `previous` is the stored entry at (ix - 1, ia); unused (may be null)
// for ix = 0.
shader::LtcEntry fitLtcEntry(int index, const LtcFitSettings& settings, const shader::LtcEntry* previous);

// Fits the rows (alpha indices) listed (all when empty), each from ix = 0 to xCount - 1, on settings.threads threads;
// `progress(done, total)` (entries) is called from the calling thread. Entries of rows not listed are left zero.
// Anisotropic: the rows are the chains ir * alphaCount + ia.
std::vector<shader::LtcEntry> fitLtcRows(const LtcFitSettings& settings, const std::vector<int>& rows,
                                         const std::function<void(int, int)>& progress);

// The number of entries of the table the settings describe, and of entries per row (chain).
int ltcEntryCount(const LtcFitSettings& settings);
int ltcRowLength(const LtcFitSettings& settings);

}  // namespace tyndall::tables
