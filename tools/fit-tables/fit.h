// The LTSD fitter (tyndall-fit-tables): fits the HG tables of the LTSD paper (000, Sec. 5.4 and 7), deterministically,
// and single entry pairs for the lobes of Rayleigh and the Mie presets (docs/tables.md, "Other phase functions").
//
// By symmetry the fitted matrices have one free parameter: HG's hemispheres and both source distributions are
// rotationally symmetric about z, so the best M commutes with rotations about z and keeps the horizon, M = diag(m, m, 1)
// up to a scale that an LTSD ignores (docs/tables.md). Each entry is a one-dimensional minimisation over ln m: a scan
// on a fixed grid, then golden-section search, on one of two losses:
//  - "sw" (default): the sliced Wasserstein loss of 002 (Sec. 4) on fixed quasi-random samples and projection
//    directions, the paper's method;
//  - "tv": the total-variation distance between the fitted and the target hemisphere, by fixed quadrature
//    (ltsdTotalVariation), which bounds the error of every polygon integral; 14 times faster, better for |g| < 0.8 and
//    worse near |g| = 1 (docs/tables.md), so not the default.
// No random numbers are drawn; entries are independent, so the result does not depend on the thread count.
#pragma once

#include "tyndall/tables/ltsd_table.h"

#include <functional>
#include <string>
#include <vector>

namespace tyndall::tables {

struct FitSettings {
    std::string phase = "hg";  // the table's type: hg (over g), or parameterless: rayleigh, hazy-mie, murky-mie
    std::string loss = "sw";   // "sw" (default: it fits best, docs/tables.md) or "tv"
    int entriesPerHalf = 128;  // n, per half of the table
    float gMax = 0.99f;        // the table's g range is [-gMax, gMax]
    int swSamples = 2048;      // sw: samples per distribution
    int swDirections = 32;     // sw: projection directions
    int threads = 0;           // 0: all hardware threads
};

nlohmann::json settingsToJson(const FitSettings& settings);

// Fits M = diag(m, m, 1) for the upper hemisphere of HG at g with the given source; returns m.
double fitEntryScale(double g, int source, const FitSettings& settings);

// The complete entry i of a table with these settings (M, amplitude by exact integration, source, g). For a
// parameterless phase (rayleigh, hazy-mie, murky-mie) entry 0 fits the upper hemisphere of its lobe, entry 1 the lower
// one, each with the source (clamped or inverse clamped cosine) whose loss is smaller.
shader::LtsdEntry fitEntry(int index, const FitSettings& settings);

// Fits the entries listed (all when empty) on settings.threads threads; `progress(done, total)` is called from the
// calling thread. Entries not listed are left zero.
std::vector<shader::LtsdEntry> fitEntries(const FitSettings& settings, const std::vector<int>& indices,
                                          const std::function<void(int, int)>& progress);

}  // namespace tyndall::tables
