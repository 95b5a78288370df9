// The Pegoraro technique's scene, prepared once per render for both paths: the std430 arrays of
// shaders/shared/pegoraro_scene.h, the BVH, and what the render reports (truncation errors).
#pragma once

#include "pegoraro/coefficients.h"

#include "shared/pegoraro_scene.h"
#include "tyndall/core/params.h"
#include "tyndall/core/scene.h"
#include "tyndall/framework/bound_scene.h"
#include "tyndall/framework/device.h"
#include "tyndall/gpu/bvh.h"

#include <string>
#include <vector>

namespace tyndall::pegoraro {

// Auto: float on the GPU while the closed form's order is at most kAutoFloatMaxOrder (float is accurate to ~1e-5
// there, docs/pegoraro.md), double above it and on the CPU.
enum class Precision { Auto, Float, Double };
inline constexpr int kAutoFloatMaxOrder = 4;

// fallback = never is refused where the closed form's error bound (pegoraroIntegral's, refined by
// pegoraroSeriesRefine) exceeds this relative error on a set of test configurations: its rounding grows with the order
// and the size of the polynomials' coefficients, up to garbage (docs/pegoraro.md, Sec. 5).
inline constexpr double kNeverMaxError = 1e-2;

struct Settings {
    Device device = Device::Auto;
    Precision precision = Precision::Auto;
    int supersampling = 2;
    bool shadows = true;
    HgSettings hg;
    int fallbackMode = shader::kPegoraroFallbackAuto;
    double fallbackTolerance = 1e-4;
    double quadratureTolerance = 1e-6;
};

Settings settingsFrom(const ParamSet& params);

struct PreparedScene {
    shader::PegoraroFrame frame{};
    std::vector<shader::PegoraroLight> lights;
    std::vector<shader::PegoraroMedium> media;
    std::vector<glm::vec2> coefficients;             // (hi, lo) float pairs, value = hi + lo
    std::vector<shader::SurfaceTriangle> triangles;  // never empty (a dummy when the scene has no triangle)
    std::size_t triangleCount = 0;                   // the scene's triangles
    std::vector<shader::MaterialParams> materials;
    gpu::Bvh bvh;
    int maxTerms = 1;                     // the largest N = N_phi + N_I - 1 over (medium, light) pairs
    std::vector<PhasePolynomial> phases;  // per medium, for the report
};

// Throws InputError for scene content the technique cannot render or that is inconsistent.
PreparedScene prepareScene(const Scene& scene, const Settings& settings, const std::string& projectDir);

// The largest error bound of the closed form for the phase function of medium m and the distribution of light l, in
// double or float, over 64 fixed pseudo-random configurations (geometry, optical depth, interval), relative to the
// brightest that configuration could be (its isotropic integral times the maxima of both polynomials). Needs a
// SceneScope.
double closedFormErrorEstimate(const PreparedScene& scene, int m, int l, bool useDouble);

// Throws InputError (field hgTerms) when fallback = never asks for the closed form where closedFormErrorEstimate
// exceeds kNeverMaxError for some pair (medium, light).
void checkClosedFormRange(const PreparedScene& scene, const Settings& settings, bool useDouble);

// Binds a prepared scene to the calling thread for the C++ definitions of the accessors of pegoraro_scene.h (and its
// BVH for bvh.h's), so that the shared per-pixel renderer runs on the CPU. The scene must outlive the scope.
class SceneScope : public BoundScene<PreparedScene>::Binding {
public:
    explicit SceneScope(const PreparedScene& scene) : Binding(scene, scene.bvh) {}
};

}  // namespace tyndall::pegoraro
