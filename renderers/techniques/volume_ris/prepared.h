// The Volume-RIS technique's scene, prepared once per render for both paths: the std430 arrays of
// shaders/shared/volume_ris.h (frame, planes, lights, light vertices, surfaces) and the BVH.
#pragma once

#include "tyndall/framework/gpu_surfaces.h"

#include "shared/volume_ris.h"
#include "tyndall/core/params.h"
#include "tyndall/core/scene.h"
#include "tyndall/framework/bound_scene.h"
#include "tyndall/framework/device.h"

#include <string>
#include <vector>

namespace tyndall::volume_ris {

struct Settings {
    Device device = Device::Auto;
    int candidates = 32;       // M
    int samplesPerPixel = 16;  // camera rays per pixel when the request does not say
    int distanceSampling = shader::kRisTransmittance;
    int lightSampling = shader::kRisSolidAngle;
    bool shadows = true;
};

Settings settingsFrom(const ParamSet& params);

struct PreparedScene {
    shader::RisFrame frame{};
    std::vector<glm::vec4> planes;    // the medium's half-spaces (one dummy when there are none)
    std::vector<shader::RisLight> lights;
    std::vector<glm::vec4> vertices;  // every light's polygon, with the fan's cumulative area fractions in w
    GpuSurfaces surfaces;
    bool grey = true;  // the medium's extinction is the same in every channel
};

// Throws InputError for scene content the technique cannot render (checked by `supports` before) or that is
// inconsistent: more than one medium, too many lights, planes or vertices.
PreparedScene prepareScene(const Scene& scene, const Settings& settings, std::uint64_t seed,
                           const std::string& projectDir);

// Binds a prepared scene to the calling thread for the C++ definitions of volume_ris.h's accessors (and its BVH for
// bvh.h's), so that the shared renderer runs on the CPU. The scene must outlive the scope.
class SceneScope : public BoundScene<PreparedScene>::Binding {
public:
    explicit SceneScope(const PreparedScene& scene) : Binding(scene, scene.surfaces.bvh) {}
};

}  // namespace tyndall::volume_ris
