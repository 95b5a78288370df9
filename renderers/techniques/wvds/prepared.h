// The WVDS technique's scene, prepared once per render for both paths: the std430 arrays of
// shaders/shared/wvds_scene.h (frame, planes, lights, surfaces) and the BVH.
#pragma once

#include "tyndall/framework/gpu_surfaces.h"

#include "shared/wvds_scene.h"
#include "tyndall/core/params.h"
#include "tyndall/core/scene.h"
#include "tyndall/framework/bound_scene.h"
#include "tyndall/framework/device.h"

#include <string>
#include <vector>

namespace tyndall::wvds {

struct Settings {
    Device device = Device::Auto;
    int estimator = shader::kWvdsMcwvds;
    int samplesPerPixel = 16;  // camera rays per pixel when the request does not say
    int raySamples = 1;        // distance samples per camera ray
    bool shadows = true;
    bool lightSelection = true;
    double pdfScale = 1.0;
    bool denoise = false;  // ratio estimators: numerator and denominator denoised separately before the ratio
};

// The estimator names of the `estimator` parameter, indexed by shader::kWvds*.
const std::vector<std::string>& estimatorNames();
int estimatorFromName(const std::string& name);  // throws InputError for an unknown one

Settings settingsFrom(const ParamSet& params);

struct PreparedScene {
    shader::WvdsFrame frame{};
    std::vector<glm::vec4> planes;  // the medium's, then each light's beam planes
    std::vector<shader::WvdsLight> lights;
    GpuSurfaces surfaces;
    bool box = false;  // the medium is a box: planes in pairs of opposite normals (shaders may use TY_WVDS_BOX)
};

// Throws InputError for scene content the technique cannot render (checked by the technique before) or that is
// inconsistent: not exactly one bounded medium, too many lights or faces.
PreparedScene prepareScene(const Scene& scene, const Settings& settings, std::uint64_t seed,
                           const std::string& projectDir);

// Binds a prepared scene to the calling thread for the C++ definitions of the accessors of wvds_scene.h (and its BVH
// for bvh.h's), so that the shared renderer runs on the CPU. The scene must outlive the scope.
class SceneScope : public BoundScene<PreparedScene>::Binding {
public:
    explicit SceneScope(const PreparedScene& scene) : Binding(scene, scene.surfaces.bvh) {}
};

}  // namespace tyndall::wvds
