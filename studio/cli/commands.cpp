#include "commands.h"

#include "progress.h"

#include "tyndall/core/error.h"
#include "tyndall/core/output.h"
#include "tyndall/core/text.h"
#include "tyndall/gpu/context.h"
#include "tyndall/image/colour_management.h"
#include "tyndall/image/flip.h"
#include "tyndall/image/image_io.h"
#include "tyndall/image/merge.h"
#include "tyndall/image/metrics.h"
#include "tyndall/project/project.h"
#include "tyndall/techniques/registry.h"
#include "tyndall/techniques/render.h"

#include <nlohmann/json.hpp>
#include <tbb/info.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iostream>
#include <optional>
#include <sstream>

namespace tyndall::cli {

namespace {

std::atomic<bool> gCancel{false};
void onInterrupt(int) { gCancel.store(true); }

}  // namespace

bool renderCancelled() {
    return gCancel.load();
}

int guarded(const std::function<int()>& body) {
    try {
        return body();
    } catch (const InputError& e) {
        std::fprintf(stderr, "tyndall: error: %s\n", e.what());
        return kBadInput;
    } catch (const OutputError& e) {
        std::fprintf(stderr, "tyndall: error: %s\n", e.what());
        return kFailure;
    } catch (const Cancelled&) {
        std::fprintf(stderr, "tyndall: cancelled\n");
        return kFailure;
    } catch (const std::bad_alloc&) {
        std::fprintf(stderr, "tyndall: error: out of memory\n");
        return kFailure;
    } catch (const std::exception& e) {
        std::fprintf(stderr, "tyndall: failure: %s\n", e.what());
        return kFailure;
    }
}

namespace {

std::string extensionOf(const std::string& path) {
    std::string ext = std::filesystem::path(path).extension().string();
    for (char& c : ext) c = char(std::tolower(static_cast<unsigned char>(c)));
    return ext;
}

void checkOutputPath(const std::string& path) {
    std::string ext = extensionOf(path);
    if (ext != ".exr" && ext != ".png")
        throw InputError(InputLocation{"", 0, 0, "--out"}, "'" + path + "' must end in .exr or .png");
    std::filesystem::path dir = std::filesystem::path(path).parent_path();
    if (!dir.empty() && !std::filesystem::is_directory(dir))
        throw InputError(InputLocation{"", 0, 0, "--out"}, "the folder of '" + path + "' does not exist");
}

constexpr int kMaxImageSide = 16384;  // as camera.width and camera.height (docs/project-format.md)

// "WxH" -> camera overrides.
void addSizeOverrides(const std::string& size, std::vector<std::string>& sets) {
    int w = 0, h = 0;
    char x = 0, rest = 0;
    std::istringstream in(size);
    if (!(in >> w >> x >> h) || (x != 'x' && x != 'X') || (in >> rest))
        throw InputError(InputLocation{"", 0, 0, "--size"}, "'" + size + "' is not WIDTHxHEIGHT, e.g. 512x512");
    if (w < 1 || h < 1 || w > kMaxImageSide || h > kMaxImageSide)
        throw InputError(InputLocation{"", 0, 0, "--size"}, "'" + size + "': width and height must be in [1, " +
                                                                std::to_string(kMaxImageSide) + "]");
    sets.push_back("camera.width=" + std::to_string(w));
    sets.push_back("camera.height=" + std::to_string(h));
}

Region parseRegion(const std::string& text) {
    Region r;
    if (text.empty()) return r;
    char c1 = 0, c2 = 0, c3 = 0;
    std::istringstream in(text);
    if (!(in >> r.x >> c1 >> r.y >> c2 >> r.width >> c3 >> r.height) || c1 != ',' || c2 != ',' || c3 != ',' ||
        r.width <= 0 || r.height <= 0)
        throw InputError(InputLocation{"", 0, 0, "--region"}, "'" + text + "' is not x,y,width,height with a positive size");
    return r;
}

// --json and --csv: a folder named instead of a file is the user's mistake, not the environment's.
void checkTextOutputPath(const std::string& path, const char* field) {
    std::error_code ec;
    if (std::filesystem::is_directory(path, ec))
        throw InputError(InputLocation{"", 0, 0, field}, "'" + path + "' is a directory; name a file");
}

// The exposure a reference image carries in its metadata (Tyndall writes the view's), for PSNR; 0 when absent.
double exposureFromMetadata(const Image& reference, const std::string& path) {
    const auto it = reference.metadata.find("exposure");
    if (it == reference.metadata.end()) return 0.0;
    const std::string& text = it->second;
    char* end = nullptr;
    const double exposure = std::strtod(text.c_str(), &end);
    if (text.empty() || end != text.c_str() + text.size() || !std::isfinite(exposure) || std::abs(exposure) > 20.0)
        throw InputError(
            InputLocation{path, 0, 0, "metadata.exposure"},
            "must be a number of stops in [-20, 20], got '" + text.substr(0, 60) + "' (or give --exposure)");
    return exposure;
}

// "1 view", "3 views".
std::string counted(std::size_t n, const char* noun) {
    return std::to_string(n) + " " + noun + (n == 1 ? "" : "s");
}

// Warns on stderr of what a render leaves out of the scene (a view without its own lights/media).
void warnLeftOut(const RenderJob& job, const std::string& prefix) {
    if (job.leftOut.empty()) return;
    std::fprintf(stderr, "%swarning: %s leaves out what its technique cannot render (name them in the view's "
                         "\"lights\"/\"media\" to make this an error):\n", prefix.c_str(), job.label.c_str());
    for (const std::string& line : job.leftOut) std::fprintf(stderr, "%s  %s\n", prefix.c_str(), line.c_str());
}

}  // namespace

std::uint64_t shardSeed(std::uint64_t seed, int shard) {
    if (shard == 0) return seed;
    // SplitMix64's finaliser of the seed offset by the shard's multiple of the golden ratio.
    std::uint64_t z = seed + 0x9e3779b97f4a7c15ull * std::uint64_t(shard);
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
    return z ^ (z >> 31);
}

namespace {

// --shard I/N: the job renders the I-th of N equal shares of its samples per pixel (the first S mod N shares one more)
// with shardSeed's seed, and says so in its metadata.
void applyShard(RenderJob& job, const std::string& text, bool timeBound) {
    const auto bad = [&](const std::string& why) {
        return InputError(InputLocation{"", 0, 0, "--shard"}, why + ", got '" + text + "'");
    };
    const std::size_t slash = text.find('/');
    int index = -1, count = 0;
    try {
        std::size_t used = 0;
        if (slash == std::string::npos) throw bad("must be I/N");
        index = std::stoi(text.substr(0, slash), &used);
        if (used != slash) throw bad("must be I/N");
        count = std::stoi(text.substr(slash + 1), &used);
        if (used != text.size() - slash - 1) throw bad("must be I/N");
    } catch (const InputError&) {
        throw;
    } catch (const std::exception&) {
        throw bad("must be I/N with whole numbers");
    }
    if (count < 1 || index < 0 || index >= count) throw bad("must be I/N with 0 <= I < N");
    if (timeBound) throw bad("shards share a sample count; leave --time out");
    const int total = job.request.spp;
    if (total <= 0 || total >= RenderRequest::kUnboundedSpp) throw bad("needs a sample count to share (--spp)");
    const int share = total / count + (index < total % count ? 1 : 0);
    if (share < 1)
        throw bad("leaves shard " + std::to_string(index) + " without samples (" + std::to_string(total) + " spp in " +
                  std::to_string(count) + " shards)");
    job.request.spp = share;
    job.metadata["shard"] = std::to_string(index) + "/" + std::to_string(count);
    job.metadata["shardBaseSeed"] = std::to_string(job.request.seed);
    job.request.seed = shardSeed(job.request.seed, index);
}

DisplayTransform pngDisplayTransform(const RenderArgs& args, const std::vector<std::string>& outs) {
    const bool png = std::any_of(outs.begin(), outs.end(), [](const std::string& out) {
        return std::filesystem::path(out).extension() == ".png";
    });
    std::shared_ptr<const ColourConfig> config;
    if (args.tonemap.empty() && (png || !args.ocio.empty() || !args.display.empty() || !args.ocioView.empty())) {
        config = ColourConfig::load(args.ocio, "--ocio");
        for (const std::string& warning : config->warnings())
            std::fprintf(stderr, "tyndall: %s\n", warning.c_str());
    }
    if (!config && args.tonemap.empty()) return {};  // no PNG: nothing is shown
    return displayTransformFromOptions(config, args.tonemap, args.display, args.ocioView);
}

}  // namespace

int merge(const MergeArgs& args) {
    return guarded([&] {
        if (std::filesystem::path(args.out).extension() != ".exr")
            throw InputError(InputLocation{args.out, 0, 0, "--out"}, "the merged image must be an .exr");
        checkOutputPath(args.out);
        std::vector<Image> images;
        for (const std::string& path : args.images)
            images.push_back(readLinearExr(path, "images"));
        const Image merged = mergeRenders(images, args.images);
        OutputSet files;
        files.stage(args.out, encodeImage(merged, args.out));
        files.commit();
        std::printf("wrote %s (%d x %d, %s spp from %zu shards)\n", args.out.c_str(), merged.width(), merged.height(),
                    merged.metadata.at("spp").c_str(), images.size());
        return int(kOk);
    });
}

int render(const RenderArgs& args) {
    return guarded([&] {
        std::vector<std::string> sets = args.sets;
        if (!args.size.empty()) addSizeOverrides(args.size, sets);
        if (args.spp && *args.spp < 1)
            throw InputError(InputLocation{"", 0, 0, "--spp"}, "must be at least 1, got " + std::to_string(*args.spp));
        if (args.time && !(*args.time > 0.0))
            throw InputError(InputLocation{"", 0, 0, "--time"}, "must be a positive number of seconds");
        if (!args.reference && args.view.empty())
            throw InputError(InputLocation{"", 0, 0, "--view"},
                             "name a view with --view, or render the reference with --reference");
        std::vector<std::string> outs = args.outs;
        if (outs.empty()) {
            std::string stem = std::filesystem::path(args.project).stem().string();
            outs.push_back(stem + "-" + (args.reference ? std::string("reference") : args.view) +
                           (args.reference && !args.view.empty() ? "-" + args.view : std::string()) + ".exr");
        }
        for (const std::string& out : outs) checkOutputPath(out);
        // The PNGs' display transform, decided (and its options checked) before anything renders: Tyndall's operator
        // with --tonemap, else a display and view of the OpenColorIO config (colour_management.h).
        const DisplayTransform display = pngDisplayTransform(args, outs);

        Project project = loadProject(techniqueCatalogue(), args.project, sets);
        JobOptions options;
        options.spp = args.spp;
        options.timeLimit = args.time;
        options.seed = args.seed;
        options.threads = args.threads;
        RenderJob job = args.reference ? makeReferenceJob(project, args.project, args.view, options)
                                       : makeViewJob(project, args.project, args.view, options);
        if (!args.shard.empty()) applyShard(job, args.shard, args.time.has_value());
        warnLeftOut(job, "tyndall: ");

        // Ctrl+C, and SIGTERM (Slurm's scancel and time limit), cancel the render: nothing is written.
        const auto previousInt = std::signal(SIGINT, onInterrupt);
        const auto previousTerm = std::signal(SIGTERM, onInterrupt);
        ProgressBar bar("rendering " + job.label);
        RenderCallbacks callbacks;
        callbacks.progress = [&](double f) { bar.update(f); };
        callbacks.cancel = &gCancel;
        RenderResult result = runJob(job, callbacks);
        bar.finish();
        std::signal(SIGINT, previousInt);
        std::signal(SIGTERM, previousTerm);

        if (const std::string warning = checkFiniteSamples(result); !warning.empty())
            std::fprintf(stderr, "tyndall: warning: %s\n", warning.c_str());
        const double exposure = args.exposure.value_or(job.exposure);
        OutputSet files;  // every output, or none
        for (const std::string& out : outs)
            files.stage(out, encodeImage(result.image, out, exposure, display));
        files.commit();
        for (const std::string& out : outs) {
            std::printf("wrote %s (%d x %d, %d spp, %.2f s)\n", out.c_str(), result.image.width(),
                        result.image.height(), result.spp, result.seconds);
        }
        return int(kOk);
    });
}

int probe(const ProbeArgs& args) {
    return guarded([&] {
        std::vector<std::string> sets = args.sets;
        if (!args.size.empty()) addSizeOverrides(args.size, sets);
        if (args.spp && *args.spp < 1)
            throw InputError(InputLocation{"", 0, 0, "--spp"}, "must be at least 1, got " + std::to_string(*args.spp));
        Project project = loadProject(techniqueCatalogue(), args.project, sets);
        JobOptions options;
        options.spp = args.spp;
        options.seed = args.seed;
        RenderJob job = makeViewJob(project, args.project, args.view, options);
        int x = project.scene.camera.width / 2, y = project.scene.camera.height / 2;
        if (args.pixel) {
            // Given, it must be a pixel: an empty value is not "the default" (leave the option out for the centre).
            char comma = 0, rest = 0;
            std::istringstream in(*args.pixel);
            if (!(in >> x >> comma >> y) || comma != ',' || (in >> rest))
                throw InputError(InputLocation{"", 0, 0, "--pixel"},
                                 "'" + args.pixel->substr(0, 60) +
                                     "' is not x,y, e.g. 120,80 (leave --pixel out for the image centre)");
        }
        const ProbeResult r = job.technique->probe(job.request, args.probe, x, y);
        nlohmann::json j;
        j["title"] = r.title;
        j["xLabel"] = r.xLabel;
        j["yLabel"] = r.yLabel;
        j["series"] = nlohmann::json::array();
        std::string csv = "series,x,y\n";
        for (const ProbeSeries& s : r.series) {
            j["series"].push_back({{"label", s.label}, {"x", s.x}, {"y", s.y}});
            for (std::size_t i = 0; i < s.x.size() && i < s.y.size(); ++i)
                csv += "\"" + s.label + "\"," + formatShort(s.x[i]) + "," + formatShort(s.y[i]) + "\n";
        }
        std::printf("%s\n", r.title.c_str());
        for (const ProbeSeries& s : r.series)
            std::printf("  %-40s %zu points\n", s.label.c_str(), s.x.size());
        OutputSet files;
        if (!args.csv.empty()) checkTextOutputPath(args.csv, "--csv");
        if (!args.json.empty()) checkTextOutputPath(args.json, "--json");
        if (!args.csv.empty()) files.stage(args.csv, csv);
        if (!args.json.empty()) files.stage(args.json, j.dump(2) + "\n");
        files.commit();
        return int(kOk);
    });
}

int validate(const ValidateArgs& args) {
    int worst = kOk;
    for (const std::string& path : args.projects) {
        int code = guarded([&] {
            Project project = loadProject(techniqueCatalogue(), path, args.sets);
            // Every check a render would make: each view with its technique, and the reference of the whole scene
            // (every view's reference renders a part of it), each prepared as for rendering.
            // Each view is checked on its own: every view that cannot render is reported, not only the first.
            std::size_t partial = 0;
            std::vector<std::string> errors;
            std::optional<InputError> first;
            auto check = [&](const std::function<void()>& run) {
                try {
                    run();
                } catch (const InputError& e) {
                    if (!first) first = e;
                    errors.push_back(e.what());
                }
            };
            for (const View& view : project.views)
                check([&] {
                    const RenderJob job = makeViewJob(project, path, view.name);
                    checkJob(job);
                    warnLeftOut(job, path + ": ");
                    partial += job.leftOut.empty() ? 0 : 1;
                });
            check([&] { checkJob(makeReferenceJob(project, path, "")); });
            if (errors.size() == 1) throw *first;
            if (!errors.empty()) {
                std::string message = first->message();
                for (std::size_t i = 1; i < errors.size(); ++i)
                    message += "\n" + errors[i];
                throw InputError(first->where(), message + "\n(" + std::to_string(errors.size()) + " errors)");
            }
            std::printf("%s: ok (%s%s)\n", path.c_str(), counted(project.views.size(), "view").c_str(),
                        partial ? (", " + std::to_string(partial) + " leaving out part of the scene").c_str() : "");
            return int(kOk);
        });
        worst = std::max(worst, code);
    }
    return worst;
}

int compare(const CompareArgs& args) {
    return guarded([&] {
        if (args.images.empty()) throw InputError(InputLocation{"", 0, 0, "images"}, "name at least one image to compare");
        const Region region = parseRegion(args.region);
        DifferenceKind kind;
        if (args.diffKind == "signed") kind = DifferenceKind::Signed;
        else if (args.diffKind == "absolute") kind = DifferenceKind::Absolute;
        else if (args.diffKind == "relative") kind = DifferenceKind::Relative;
        else throw InputError(InputLocation{"", 0, 0, "--diff-kind"}, "'" + args.diffKind + "' is not one of signed, absolute, relative");
        if (!(args.diffScale >= 0.0) || !std::isfinite(args.diffScale))
            throw InputError(InputLocation{"", 0, 0, "--diff-scale"}, "must be a finite number >= 0 (0: the default)");
        if (!args.diff.empty()) checkOutputPath(args.diff);
        if (!args.csv.empty()) checkTextOutputPath(args.csv, "--csv");
        if (!args.json.empty()) checkTextOutputPath(args.json, "--json");
        if (!args.diff.empty() && args.images.size() > 1 && args.diff.find("{name}") == std::string::npos)
            throw InputError(InputLocation{"", 0, 0, "--diff"}, "with several images the path must contain {name}");
        bool flip = false;
        for (const std::string& metric : args.metrics) {
            if (metric != "flip")
                throw InputError(InputLocation{"", 0, 0, "--metric"},
                                 "'" + metric +
                                     "' is not an extra metric; the one there is: flip (RMSE, relMSE, MAPE, "
                                     "PSNR and the energy bias are always computed)");
            flip = true;
        }
        for (const std::string& map : args.flipMaps) {
            if (!flip) throw InputError(InputLocation{"", 0, 0, "--flip-map"}, "needs --metric flip");
            const std::string ext = std::filesystem::path(map).extension().string();
            if (ext != ".exr" && ext != ".png")
                throw InputError(InputLocation{map, 0, 0, "--flip-map"},
                                 "must name an .exr (the error and its exposure) or a .png (the error in magma) file");
            if (args.images.size() > 1 && map.find("{name}") == std::string::npos)
                throw InputError(InputLocation{"", 0, 0, "--flip-map"},
                                 "with several images the path must contain {name}");
            checkOutputPath(map);
        }
        if (!args.flipHistogram.empty()) {
            if (!flip) throw InputError(InputLocation{"", 0, 0, "--flip-histogram"}, "needs --metric flip");
            if (args.images.size() > 1 && args.flipHistogram.find("{name}") == std::string::npos)
                throw InputError(InputLocation{"", 0, 0, "--flip-histogram"},
                                 "with several images the path must contain {name}");
            checkTextOutputPath(args.flipHistogram, "--flip-histogram");
        }
        if (!(args.pixelsPerDegree >= 0.0))
            throw InputError(InputLocation{"", 0, 0, "--ppd"}, "must be a positive number of pixels per degree");
        HdrFlipSettings flipSettings;
        if (args.pixelsPerDegree > 0.0) flipSettings.pixelsPerDegree = args.pixelsPerDegree;
        try {
            flipSettings.toneMapper = flipToneMapperFromName(args.toneMapper);
        } catch (const InputError& e) {
            throw InputError(InputLocation{"", 0, 0, "--tone-mapper"}, e.message());
        }

        // Every input is read (and checked) before anything is computed or written.
        const Image reference = readLinearExr(args.reference, "--reference");
        std::vector<Image> images;
        for (const std::string& path : args.images)
            images.push_back(readLinearExr(path, "images"));
        const double exposure = args.exposure ? *args.exposure : exposureFromMetadata(reference, args.reference);

        // One difference scale for every image against this reference: 10 % of the reference's mean luminance by
        // default, never each image's own range.
        double scale = args.diffScale;
        if (scale == 0.0) {
            double sum = 0.0;
            Image rgb = reference.select({"R", "G", "B"});
            for (int y = 0; y < rgb.height(); ++y)
                for (int x = 0; x < rgb.width(); ++x)
                    sum += 0.2126 * rgb.at(x, y, 0) + 0.7152 * rgb.at(x, y, 1) + 0.0722 * rgb.at(x, y, 2);
            scale = std::max(1e-6, 0.1 * sum / (double(rgb.width()) * rgb.height()));
        }

        nlohmann::json json = nlohmann::json::object();
        json["reference"] = args.reference;
        json["exposure"] = exposure;
        json["differenceScale"] = scale;
        json["images"] = nlohmann::json::array();
        std::string csv = metricsCsvHeader() + "\n";
        std::printf("%-32s %12s %12s %10s %10s %10s\n", "image", "RMSE", "relMSE", "MAPE %", "PSNR dB", "bias %");
        OutputSet files;  // the difference images, JSON and CSV appear together or not at all
        for (std::size_t i = 0; i < args.images.size(); ++i) {
            const std::string& path = args.images[i];
            const Image& image = images[i];
            Metrics m;
            try {
                m = computeMetrics(image, reference, exposure, region);
            } catch (const InputError& e) {
                throw InputError(InputLocation{path, 0, 0, ""}, e.message() + " (against the reference '" + args.reference + "')");
            }
            std::string name = std::filesystem::path(path).stem().string();
            std::printf("%-32s %12s %12s %10s %10s %10s\n", name.c_str(), formatShort(m.rmse).c_str(),
                        formatShort(m.relMSE).c_str(), formatShort(m.mape).c_str(), formatShort(m.psnr).c_str(),
                        formatShort(m.energyBias).c_str());
            nlohmann::json entry = metricsToJson(m);
            entry["image"] = path;
            json["images"].push_back(entry);
            csv += metricsCsvRow(name, m) + "\n";
            if (flip) {
                const HdrFlipResult r = hdrFlip(reference, image, flipSettings);
                // The statistics over the region (the whole image by default), as the other metrics.
                const int rx = region.width > 0 ? region.x : 0, ry = region.height > 0 ? region.y : 0;
                const int rw = region.width > 0 ? region.width : image.width();
                const int rh = region.height > 0 ? region.height : image.height();
                std::vector<float> errors;
                for (int y = ry; y < ry + rh; ++y)
                    for (int x = rx; x < rx + rw; ++x)
                        errors.push_back(r.error[std::size_t(y) * image.width() + x]);
                const FlipStatistics s = flipStatistics(errors);
                std::printf(
                    "%-32s FLIP mean %s, weighted median %s, weighted quartiles %s and %s, max %s (HDR-FLIP, "
                    "%s, %s ppd, exposures %s to %s in %d)\n",
                    "", formatShort(s.mean).c_str(), formatShort(s.weightedMedian).c_str(),
                    formatShort(s.weightedFirstQuartile).c_str(), formatShort(s.weightedThirdQuartile).c_str(),
                    formatShort(s.maximum).c_str(), args.toneMapper.c_str(),
                    formatShort(flipSettings.pixelsPerDegree).c_str(), formatShort(r.startExposure).c_str(),
                    formatShort(r.stopExposure).c_str(), r.exposures);
                json["images"].back()["flip"] = {{"mean", s.mean},
                                                 {"weightedMedian", s.weightedMedian},
                                                 {"weightedFirstQuartile", s.weightedFirstQuartile},
                                                 {"weightedThirdQuartile", s.weightedThirdQuartile},
                                                 {"minimum", s.minimum},
                                                 {"maximum", s.maximum},
                                                 {"pixelsPerDegree", flipSettings.pixelsPerDegree},
                                                 {"toneMapper", args.toneMapper},
                                                 {"startExposure", r.startExposure},
                                                 {"stopExposure", r.stopExposure},
                                                 {"exposures", r.exposures}};
                if (!args.flipHistogram.empty()) {
                    std::string out = args.flipHistogram;
                    if (auto pos = out.find("{name}"); pos != std::string::npos) out.replace(pos, 6, name);
                    checkTextOutputPath(out, "--flip-histogram");
                    std::string text = "low,high,pixels,weightedShare\n";
                    for (const FlipHistogramBin& b : flipHistogram(errors))
                        text += formatNumber(b.low) + "," + formatNumber(b.high) + "," + std::to_string(b.pixels) +
                                "," + formatNumber(b.weightedShare) + "\n";
                    files.stage(out, text);
                }
                for (const std::string& mapPath : args.flipMaps) {
                    std::string out = mapPath;
                    if (auto pos = out.find("{name}"); pos != std::string::npos) out.replace(pos, 6, name);
                    checkOutputPath(out);
                    if (std::filesystem::path(out).extension() == ".png") {
                        files.stage(out, encodeImage(flipColourMap(r.error, image.width(), image.height()), out));
                        continue;
                    }
                    Image map(image.width(), image.height(), {"FLIP", "exposure"});
                    for (int y = 0; y < image.height(); ++y)
                        for (int x = 0; x < image.width(); ++x) {
                            const std::size_t k = std::size_t(y) * image.width() + x;
                            map.at(x, y, 0) = r.error[k];
                            map.at(x, y, 1) =
                                float(r.startExposure + (r.stopExposure - r.startExposure) * r.exposureIndex[k] /
                                                            std::max(r.exposures - 1, 1));
                        }
                    map.metadata["flip:mean"] = formatShort(s.mean);
                    map.metadata["flip:toneMapper"] = args.toneMapper;
                    map.metadata["flip:pixelsPerDegree"] = formatShort(flipSettings.pixelsPerDegree);
                    files.stage(out, encodeImage(map, out));
                }
            }
            if (!args.diff.empty()) {
                std::string out = args.diff;
                if (auto pos = out.find("{name}"); pos != std::string::npos) out.replace(pos, 6, name);
                checkOutputPath(out);
                files.stage(out, encodeImage(differenceImage(image, reference, kind, scale), out));
            }
        }
        if (auto noise = computeMetrics(reference, reference, exposure, region).referenceNoiseRelMSE)
            std::printf("reference noise (relMSE from its variance): %s\n", formatShort(*noise).c_str());
        if (!args.json.empty()) files.stage(args.json, json.dump(2) + "\n");
        if (!args.csv.empty()) files.stage(args.csv, csv);
        files.commit();
        if (!args.diff.empty()) {
            for (const std::string& path : args.images) {
                std::string out = args.diff;
                if (auto pos = out.find("{name}"); pos != std::string::npos)
                    out.replace(pos, 6, std::filesystem::path(path).stem().string());
                std::printf("wrote %s\n", out.c_str());
            }
        }
        return int(kOk);
    });
}

int info(const InfoArgs& args) {
    return guarded([&] {
        nlohmann::json j;
        j["tyndall"] = tyndallVersion();
        j["devices"] = nlohmann::json::array();
        j["devices"].push_back({{"name", "CPU"}, {"threads", tbb::info::default_concurrency()}, {"used by", "reference"}});
        std::string vulkanProblem;
        try {
            for (const gpu::DeviceInfo& d : gpu::Context::enumerateDevices()) {
                j["devices"].push_back({{"name", d.name},
                                        {"vulkan", std::to_string(VK_API_VERSION_MAJOR(d.apiVersion)) + "." +
                                                       std::to_string(VK_API_VERSION_MINOR(d.apiVersion))},
                                        {"index", d.index},
                                        {"type", d.typeName()},
                                        {"driver", d.driver},
                                        {"timestamps", d.timestampPeriod > 0.0f},
                                        {"geometryShader", d.geometryShader},
                                        {"float64", d.shaderFloat64},
                                        {"rayQuery", d.rayQuery},
                                        {"meshShader", d.meshShader},
                                        {"timelineSemaphores", d.timelineSemaphores}});
            }
        } catch (const gpu::GpuError& e) {
            vulkanProblem = e.what();
        }
        if (vulkanProblem.empty() && j["devices"].size() == 1) vulkanProblem = "the Vulkan loader found no device";
        if (!vulkanProblem.empty()) j["vulkanError"] = vulkanProblem;
        // The OpenColorIO config PNGs go through (render --display, --ocio-view), with its displays and views.
        const std::shared_ptr<const ColourConfig> colour = ColourConfig::load(args.ocio, "--ocio");
        for (const std::string& warning : colour->warnings())
            std::fprintf(stderr, "tyndall: %s\n", warning.c_str());
        nlohmann::json displays = nlohmann::json::object();
        for (const std::string& display : colour->displays())
            displays[display] = colour->views(display);
        j["colour"] = {{"config", colour->file().empty() ? "raw" : colour->file()},
                       {"origin", colour->origin()},
                       {"defaultDisplay", colour->defaultDisplay()},
                       {"defaultView", colour->defaultView(colour->defaultDisplay())},
                       {"displays", displays}};
        j["techniques"] = nlohmann::json::array();
        for (const std::string& name : techniqueNames()) {
            auto technique = createTechnique(name);
            nlohmann::json t;
            t["name"] = name;
            t["displayName"] = technique->displayName();
            t["parameters"] = nlohmann::json::array();
            for (const ParamInfo& p : technique->parameters()) {
                nlohmann::json pj{{"name", p.name}, {"type", toString(p.type)}, {"default", toString(p.defaultValue)},
                                  {"doc", p.doc}, {"unit", p.unit}};
                if (p.type == ParamType::Enum) pj["values"] = p.enumValues;
                else if (p.type != ParamType::Bool) pj["range"] = {p.min, p.max};
                t["parameters"].push_back(pj);
            }
            t["probes"] = nlohmann::json::array();
            for (const ProbeInfo& p : technique->probes())
                t["probes"].push_back({{"name", p.name}, {"doc", p.doc}});
            j["techniques"].push_back(t);
        }
        // Without a Vulkan device the rest of the information is still printed, and the exit status says so (1), with
        // one line on stderr: a script that needs a GPU checks `tyndall info`.
        const auto finish = [&] {
            if (vulkanProblem.empty()) return int(kOk);
            std::fprintf(stderr, "tyndall: no Vulkan device (%s); views with device = auto render on the CPU\n",
                         vulkanProblem.c_str());
            return 1;
        };
        if (args.json) {
            std::printf("%s\n", j.dump(2).c_str());
            return finish();
        }
        std::printf("Tyndall %s\n\nDevices:\n  CPU, %d threads (reference)\n", tyndallVersion(),
                    tbb::info::default_concurrency());
        for (const auto& d : j["devices"]) {
            if (!d.contains("vulkan")) continue;
            std::printf("  Vulkan %s: [%d] %s (%s)%s%s%s\n", d["vulkan"].get<std::string>().c_str(), d["index"].get<int>(),
                        d["name"].get<std::string>().c_str(), d["type"].get<std::string>().c_str(),
                        d["float64"].get<bool>() ? ", float64" : "", d["rayQuery"].get<bool>() ? ", ray queries" : "",
                        d["meshShader"].get<bool>() ? ", mesh shaders" : "");
        }
        if (!vulkanProblem.empty()) std::printf("  Vulkan: %s\n", vulkanProblem.c_str());
        std::printf("\nColour (OpenColorIO, PNG output): %s\n", colour->describe().c_str());
        for (const std::string& display : colour->displays()) {
            std::string views;
            for (const std::string& view : colour->views(display))
                views += (views.empty() ? "" : ", ") + view;
            std::printf("  display %s%s: %s\n", display.c_str(),
                        display == colour->defaultDisplay() ? " (default)" : "", views.c_str());
        }
        std::printf("\nTechniques:\n");
        for (const auto& t : j["techniques"]) {
            std::printf("  %s - %s\n", t["name"].get<std::string>().c_str(), t["displayName"].get<std::string>().c_str());
            for (const auto& p : t["parameters"]) {
                std::string allowed = p.contains("values") ? p["values"].dump() : p.contains("range") ? p["range"].dump() : "";
                std::printf("      %-18s %-6s default %-10s %-14s %s\n", p["name"].get<std::string>().c_str(),
                            p["type"].get<std::string>().c_str(), p["default"].get<std::string>().c_str(),
                            allowed.c_str(), p["doc"].get<std::string>().c_str());
            }
            for (const auto& p : t["probes"])
                std::printf("      probe %-12s %s\n", p["name"].get<std::string>().c_str(),
                            p["doc"].get<std::string>().c_str());
        }
        return finish();
    });
}

}  // namespace tyndall::cli
