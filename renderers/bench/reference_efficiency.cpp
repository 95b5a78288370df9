// The reference's efficiency on the three scenes of issue 16 (projects/bench/*.json): error against CPU time for
// several estimator variants, measured interleaved in one run so that the machine's drift affects them alike.
//   build/renderers/bench/tyndall_reference_efficiency [SIZE=256] [MAXSPP=64] [CONVERGED_SPP=1024] [SECONDS=4]
//                                                      [--scenes=NAME,NAME] [VARIANT...]
// A VARIANT is `label:param=value,param=value` (reference parameters, e.g. `before:distanceSampling=mis`); without
// any, the defaults are compared with the estimator this benchmark was first run against.
//
// For each scene the converged image is rendered once with the default parameters, CONVERGED_SPP samples and a seed
// no run uses, and cached under the build folder (bench-cache/, keyed by the project's hash, size and spp). Each
// variant then renders 1, 2, 4, ... MAXSPP samples (variants interleaved at each spp), timed in process CPU seconds
// (every thread's); the series (spp, cpu s, RMSE, relMSE) is the log-log plot. RMSE and relMSE are corrected for the
// converged image's own noise (its variance channels: E[err^2] = MSE + var_ref), so that a good estimator is not
// floored by the reference. From the series, by log-log interpolation (extrapolation past the ends is marked):
// the CPU time to relMSE 1e-3 and the RMSE at SECONDS CPU seconds, and the ratio of each variant to the first.
// Every error is also reported with each point light's own pixels masked (a 12 x 12 block about its image, issue 32):
// there the error is that of the singular-pixel jitter, elsewhere that of the distance sampling.
#include "shared/singular_pixel.h"
#include "tyndall/core/resources.h"
#include "tyndall/framework/shader_params.h"
#include "tyndall/image/image_io.h"
#include "tyndall/image/metrics.h"
#include "tyndall/project/project.h"
#include "tyndall/techniques/registry.h"
#include "tyndall/techniques/render.h"

#include <cmath>
#include <cstdio>
#include <cstdint>
#include <cstdlib>
#include <ctime>
#include <filesystem>
#include <sstream>
#include <string>
#include <vector>

using namespace tyndall;

namespace {

const char* const kScenes[] = {"fog-point", "fog-quad", "box-shaft"};

double cpuSeconds() {
    timespec ts{};
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
    return double(ts.tv_sec) + 1e-9 * double(ts.tv_nsec);
}

struct Variant {
    std::string label;
    std::vector<std::pair<std::string, std::string>> params;
};

Variant parseVariant(const std::string& text) {
    Variant v;
    const size_t colon = text.find(':');
    v.label = text.substr(0, colon);
    if (colon == std::string::npos) return v;
    std::stringstream rest(text.substr(colon + 1));
    std::string item;
    while (std::getline(rest, item, ',')) {
        const size_t eq = item.find('=');
        if (eq == std::string::npos) continue;
        v.params.emplace_back(item.substr(0, eq), item.substr(eq + 1));
    }
    return v;
}

struct Error {
    double rmse = 0.0, relMSE = 0.0;
};

struct Point {
    int spp;
    double seconds;
    Error all, masked;  // every pixel; without the point lights' own pixels
};

// The pixels of a 12 x 12 block about each point light's image (when in front of the camera).
std::vector<char> pointLightMask(const Project& project) {
    const Camera& camera = project.scene.camera;
    std::vector<char> mask(std::size_t(camera.width) * std::size_t(camera.height), 0);
    const shader::CameraParams params = toCameraParams(camera);
    for (const PointLight& light : project.scene.pointLights) {
        glm::vec2 p;
        if (!shader::cameraProject(params, glm::vec3(light.position.x, light.position.y, light.position.z), p))
            continue;
        const int x0 = int(std::lround(p.x)) - 6, y0 = int(std::lround(p.y)) - 6;
        for (int y = std::max(0, y0); y < std::min(camera.height, y0 + 12); ++y)
            for (int x = std::max(0, x0); x < std::min(camera.width, x0 + 12); ++x)
                mask[std::size_t(y) * std::size_t(camera.width) + std::size_t(x)] = 1;
    }
    return mask;
}

// Error of `image` against the converged `ref`, less the converged image's own variance (per pixel and channel):
// RMSE and relMSE = mean(e^2 / (r^2 + 0.01)) (metrics.h), over every pixel and over those the mask leaves.
void errors(const Image& image, const Image& ref, const std::vector<char>& mask, Error& all, Error& masked) {
    const int vr = ref.channelIndex("variance.R");
    double sum[2][4] = {};  // [all, masked] x {e^2 - var, (e^2 - var) / (r^2 + 0.01), pixels}
    for (int y = 0; y < ref.height(); ++y)
        for (int x = 0; x < ref.width(); ++x) {
            double se = 0.0, rel = 0.0;
            for (int c = 0; c < 3; ++c) {
                const double r = ref.at(x, y, c), e = double(image.at(x, y, c)) - r;
                const double excess = e * e - double(ref.at(x, y, vr + c));
                se += excess;
                rel += excess / (r * r + 0.01);
            }
            const bool keep = !mask[std::size_t(y) * std::size_t(ref.width()) + std::size_t(x)];
            for (int k = 0; k < (keep ? 2 : 1); ++k) {
                sum[k][0] += se;
                sum[k][1] += rel;
                sum[k][2] += 3.0;
            }
        }
    all = {std::sqrt(std::max(0.0, sum[0][0] / sum[0][2])), std::max(0.0, sum[0][1] / sum[0][2])};
    masked = {std::sqrt(std::max(0.0, sum[1][0] / sum[1][2])), std::max(0.0, sum[1][1] / sum[1][2])};
}

// log y at log x on the series (x increasing), by linear interpolation in log-log; `extrapolated` when outside.
double logLog(const std::vector<double>& xs, const std::vector<double>& ys, double x, bool& extrapolated) {
    const size_t n = xs.size();
    size_t i = 0;
    while (i + 2 < n && xs[i + 1] < x) ++i;
    extrapolated = x < xs.front() || x > xs.back();
    const double lx0 = std::log(xs[i]), lx1 = std::log(xs[i + 1]);
    const double ly0 = std::log(ys[i]), ly1 = std::log(ys[i + 1]);
    return std::exp(ly0 + (ly1 - ly0) * (std::log(x) - lx0) / (lx1 - lx0));
}

}  // namespace

int main(int argc, char** argv) {
    const int size = argc > 1 ? std::atoi(argv[1]) : 256;
    const int maxSpp = argc > 2 ? std::atoi(argv[2]) : 64;
    const int convergedSpp = argc > 3 ? std::atoi(argv[3]) : 1024;
    const double budget = argc > 4 ? std::atof(argv[4]) : 4.0;
    std::vector<Variant> variants;
    std::vector<std::string> scenes(std::begin(kScenes), std::end(kScenes));
    for (int i = 5; i < argc; ++i) {
        const std::string arg = argv[i];
        if (arg.rfind("--scenes=", 0) == 0) {
            scenes.clear();
            std::stringstream list(arg.substr(9));
            for (std::string name; std::getline(list, name, ',');)
                scenes.push_back(name);
        } else {
            variants.push_back(parseVariant(arg));
        }
    }
    if (variants.empty()) {
        variants.push_back(parseVariant("before:distanceSampling=mis"));
        variants.push_back(parseVariant("after:"));
    }
    const std::filesystem::path cache = std::filesystem::path(TYNDALL_BINARY_DIR) / "bench-cache";
    std::filesystem::create_directories(cache);

    try {
        for (const std::string& sceneName : scenes) {
            const std::string path = (tyndall::resourceRoot() / "projects/bench" / (sceneName + ".json")).string();
            const Project project =
                loadProject(techniqueCatalogue(), path,
                            {"camera.width=" + std::to_string(size), "camera.height=" + std::to_string(size)});
            const std::string view = project.views.front().name;

            // The converged image, once.
            const std::filesystem::path cached =
                cache / (sceneName + "-" + projectHash(project) + "-" + std::to_string(convergedSpp) + ".exr");
            Image ref;
            if (std::filesystem::exists(cached)) {
                ref = readImage(cached.string());
            } else {
                JobOptions options;
                options.spp = convergedSpp;
                options.seed = 987654321;
                RenderJob job = makeReferenceJob(project, path, view, options);
                RenderResult r = runJob(job);
                ref = r.image;
                writeImage(ref, cached.string());
                std::fprintf(stderr, "%s: converged image, %d spp in %.0f s, cached as %s\n", sceneName.c_str(), r.spp,
                             r.seconds, cached.c_str());
            }

            const std::vector<char> mask = pointLightMask(project);
            std::vector<std::vector<Point>> series(variants.size());
            for (int spp = 1; spp <= maxSpp; spp *= 2) {
                for (size_t v = 0; v < variants.size(); ++v) {
                    JobOptions options;
                    options.spp = spp;
                    options.seed = 7;
                    RenderJob job = makeReferenceJob(project, path, view, options);
                    for (const auto& [name, value] : variants[v].params) {
                        const bool integer = !value.empty() && value.find_first_not_of("0123456789") == std::string::npos;
                        if (integer) job.request.params.set(name, std::int64_t(std::stoll(value)));
                        else job.request.params.set(name, value);
                    }
                    const double start = cpuSeconds();
                    RenderResult r = runJob(job);
                    Point p{spp, cpuSeconds() - start, {}, {}};
                    errors(r.image, ref, mask, p.all, p.masked);
                    series[v].push_back(p);
                }
            }

            std::printf("\n%s (%dx%d, converged %d spp)\nvariant,spp,cpu_s,rmse,relMSE,rmse_masked,relMSE_masked\n",
                        sceneName.c_str(), size, size, convergedSpp);
            for (size_t v = 0; v < variants.size(); ++v)
                for (const Point& p : series[v])
                    std::printf("%s,%d,%.3f,%.5g,%.5g,%.5g,%.5g\n", variants[v].label.c_str(), p.spp, p.seconds,
                                p.all.rmse, p.all.relMSE, p.masked.rmse, p.masked.relMSE);
            std::printf(
                "variant,pixels,log-log slope of RMSE vs time,cpu_s to relMSE 1e-3,RMSE at %.3g cpu s,"
                "ratio of RMSE to the first variant's\n",
                budget);
            for (const bool useMask : {false, true}) {
                double firstRmse = 0.0;
                for (size_t v = 0; v < variants.size(); ++v) {
                    std::vector<double> t, rmse, rel;
                    for (const Point& p : series[v]) {
                        const Error& e = useMask ? p.masked : p.all;
                        t.push_back(p.seconds);
                        rmse.push_back(e.rmse);
                        rel.push_back(e.relMSE);
                    }
                    const double slope =
                        (std::log(rmse.back()) - std::log(rmse.front())) / (std::log(t.back()) - std::log(t.front()));
                    bool exT = false, exR = false;
                    // relMSE falls with time: interpolate time as a function of relMSE on the reversed series.
                    std::vector<double> relRev(rel.rbegin(), rel.rend()), tRev(t.rbegin(), t.rend());
                    const double toTarget = logLog(relRev, tRev, 1e-3, exT);
                    const double atBudget = logLog(t, rmse, budget, exR);
                    if (v == 0) firstRmse = atBudget;
                    std::printf("%s,%s,%.3f,%.3g%s,%.5g%s,%.3f\n", variants[v].label.c_str(),
                                useMask ? "masked" : "all", slope, toTarget, exT ? " (extrapolated)" : "", atBudget,
                                exR ? " (extrapolated)" : "", atBudget / firstRmse);
                }
            }
            std::fflush(stdout);
        }
    } catch (const std::exception& e) {
        std::fprintf(stderr, "%s\n", e.what());
        return 1;
    }
    return 0;
}
