// The WVDS paper's integrator comparison (Fig. 6 and 7) on its Fig. 6 project: PSNR of each estimator against a
// converged image at 1, 4, 16 and 64 spp, averaged over 8 seeds, and at equal time (the time MCWVDS takes for 16 spp),
// on the CPU path.
//   build/renderers/bench/tyndall_wvds_convergence [WIDTH HEIGHT [CONVERGED_SPP]]     (default 256 192 8192)
// The converged image is MCWVDS at CONVERGED_SPP with a seed none of the runs use; PSNR uses the views' exposure, as
// `tyndall compare` does. Prints a table and a CSV (estimator,spp,seconds,psnr,relMSE).
#include "tyndall/core/resources.h"
#include "tyndall/image/metrics.h"
#include "tyndall/project/project.h"
#include "tyndall/techniques/registry.h"
#include "tyndall/techniques/render.h"

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

using namespace tyndall;

namespace {
const std::string kProject = (tyndall::resourceRoot() / "projects/examples/wvds-box.json").string();
}

int main(int argc, char** argv) {
    const int width = argc > 2 ? std::atoi(argv[1]) : 256, height = argc > 2 ? std::atoi(argv[2]) : 192;
    const int convergedSpp = argc > 3 ? std::atoi(argv[3]) : 8192;
    const char* estimators[] = {"mcwvds", "reds", "rees", "rm", "mcds"};
    std::vector<std::string> overrides = {"camera.width=" + std::to_string(width),
                                          "camera.height=" + std::to_string(height)};
    for (const char* e : estimators)
        overrides.push_back(std::string("views[") + e + "].parameters.device=cpu");
    const Project project = loadProject(techniqueCatalogue(), kProject, overrides);
    const double exposure = -1.0;

    auto render = [&](const std::string& view, int spp, std::uint64_t seed, double& seconds) {
        JobOptions options;
        options.spp = spp;
        options.seed = seed;
        RenderJob job = makeViewJob(project, kProject, view, options);
        const auto start = std::chrono::steady_clock::now();
        RenderResult r = runJob(job);
        seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
        return r.image;
    };
    double seconds = 0.0;
    const Image converged = render("mcwvds", convergedSpp, 999983, seconds);
    std::printf("converged: mcwvds, %d spp, %d x %d, %.1f s\n", convergedSpp, width, height, seconds);

    constexpr int kSeeds = 8;
    std::printf("\n%-8s %10s %10s %10s %10s   (PSNR dB, mean of %d seeds)\n", "", "1 spp", "4 spp", "16 spp", "64 spp",
                kSeeds);
    std::vector<std::string> csv;
    double equalTime = 0.0;
    std::vector<double> secondsPerSpp;
    for (const char* e : estimators) {
        std::printf("%-8s", e);
        double timePerSpp = 0.0;
        for (int spp : {1, 4, 16, 64}) {
            double psnr = 0.0, rel = 0.0, time = 0.0;
            for (int s = 0; s < kSeeds; ++s) {
                const Image image = render(e, spp, std::uint64_t(1 + s), seconds);
                const Metrics m = computeMetrics(image, converged, exposure);
                psnr += m.psnr / kSeeds;
                rel += m.relMSE / kSeeds;
                time += seconds / kSeeds;
            }
            if (spp == 64) timePerSpp = time / 64.0;
            if (spp == 16 && std::string(e) == "mcwvds") equalTime = time;
            std::printf(" %10.2f", psnr);
            char row[160];
            std::snprintf(row, sizeof row, "%s,%d,%.4f,%.3f,%.4g", e, spp, time, psnr, rel);
            csv.push_back(row);
        }
        secondsPerSpp.push_back(timePerSpp);
        std::printf("   %.2f ms per spp\n", timePerSpp * 1e3);
    }
    std::printf("\nequal time (%.3f s, MCWVDS's time for 16 spp):\n", equalTime);
    int i = 0;
    for (const char* e : estimators) {
        const int spp = std::max(1, int(equalTime / secondsPerSpp[std::size_t(i++)] + 0.5));
        double psnr = 0.0;
        for (int s = 0; s < kSeeds; ++s)
            psnr += computeMetrics(render(e, spp, std::uint64_t(1 + s), seconds), converged, exposure).psnr / kSeeds;
        std::printf("%-8s %5d spp  %8.2f dB\n", e, spp, psnr);
        char row[160];
        std::snprintf(row, sizeof row, "%s,%d,%.4f,%.3f,equal-time", e, spp, equalTime, psnr);
        csv.push_back(row);
    }
    std::printf("\nestimator,spp,seconds,psnr,relMSE\n");
    for (const std::string& row : csv)
        std::printf("%s\n", row.c_str());
    return 0;
}
