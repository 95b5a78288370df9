// Error against time of the reference on a project's views, as a log-log series (CSV on stdout):
//   build/renderers/bench/tyndall_convergence projects/default.json [size] [maxSpp]
// For each view, a render with 16 x maxSpp samples is the converged image; renders with 1, 2, 4, ... maxSpp samples
// (another seed) are compared with it by relMSE. Reports the first time at which relMSE <= 1e-3.
#include "tyndall/image/metrics.h"
#include "tyndall/project/project.h"
#include "tyndall/techniques/registry.h"
#include "tyndall/techniques/render.h"

#include <cstdio>
#include <cstdlib>
#include <string>

int main(int argc, char** argv) {
    using namespace tyndall;
    if (argc < 2) {
        std::fprintf(stderr, "usage: %s PROJECT [SIZE=256] [MAXSPP=64]\n", argv[0]);
        return 2;
    }
    const std::string path = argv[1];
    const int size = argc > 2 ? std::atoi(argv[2]) : 256;
    const int maxSpp = argc > 3 ? std::atoi(argv[3]) : 64;
    try {
        Project project =
            loadProject(techniqueCatalogue(), path,
                        {"camera.width=" + std::to_string(size), "camera.height=" + std::to_string(size)});
        std::printf("view,spp,seconds,relMSE\n");
        for (const View& view : project.views) {
            JobOptions converged;
            converged.spp = 16 * maxSpp;
            converged.seed = 1000;
            RenderJob refJob = makeReferenceJob(project, path, view.name, converged);
            RenderResult ref = runJob(refJob);
            std::fprintf(stderr, "%s: converged image, %d spp in %.1f s\n", view.name.c_str(), ref.spp, ref.seconds);
            double reached = -1.0;
            for (int spp = 1; spp <= maxSpp; spp *= 2) {
                JobOptions options;
                options.spp = spp;
                options.seed = 1;
                RenderJob job = makeReferenceJob(project, path, view.name, options);
                RenderResult r = runJob(job);
                Metrics m = computeMetrics(r.image, ref.image, view.exposure);
                std::printf("%s,%d,%.4f,%.6g\n", view.name.c_str(), spp, r.seconds, m.relMSE);
                std::fflush(stdout);
                if (reached < 0.0 && m.relMSE <= 1e-3) reached = r.seconds;
            }
            if (reached >= 0.0) std::fprintf(stderr, "%s: relMSE <= 1e-3 after %.2f s\n", view.name.c_str(), reached);
            else std::fprintf(stderr, "%s: relMSE <= 1e-3 not reached by %d spp\n", view.name.c_str(), maxSpp);
        }
    } catch (const std::exception& e) {
        std::fprintf(stderr, "%s\n", e.what());
        return 1;
    }
    return 0;
}
