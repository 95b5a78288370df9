// The ISV technique's scene, prepared once per render for both paths: the particles as tetrahedra (std430 array of
// shaders/shared/isv.h), the frame (one light, media, integration settings, the light's two light-space grids), the
// surfaces and their BVH, and the camera at the rendering resolution. The CPU model of every pass lives here too, so
// that the GPU renderer and the tests compare against one definition of what ISV computes.
#pragma once

#include "tyndall/framework/gpu_surfaces.h"

#include "shared/isv.h"
#include "tyndall/core/params.h"
#include "tyndall/core/scene.h"
#include "tyndall/framework/device.h"

#include <atomic>
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

namespace tyndall::isv {

// The producer of the proxies on the GPU (Sec. 2.3): a mesh shader (VK_EXT_mesh_shader), or the geometry stage, which
// runs everywhere; auto takes the mesh shader where the device has one.
enum class Proxies { Auto, Geometry, Mesh };

struct Settings {
    Device device = Device::Auto;
    Proxies proxies = Proxies::Auto;
    int integration = shader::kIsvSimpson;
    int steps = 1;                 // Simpson steps
    bool fading = true;            // Gaussian extinction (Eq. 9)
    float threshold = 1e-3f;       // early-out optical thickness (Sec. 3.11)
    float multiScatter = 0.0f;     // m of Eq. 11
    bool selfShadowing = true;     // the volumetric shadow map
    int vsmResolution = 128;       // texels per side
    int vsmSlices = 16;            // depth slices
    bool opaqueShadows = true;     // the opaque shadow map (when the scene has surfaces)
    int shadowMapResolution = 1024;
    int pcfRadius = 0;             // (2r + 1)^2 texels
    int supersampling = 1;         // S x S fragments per pixel, box filtered
    float nearPlane = 0.05f;       // m: tetrahedra reaching closer to the camera are culled (Sec. 2.3.4)
};

Settings settingsFrom(const ParamSet& params);

// The names of `integration`'s values, indexed by the kIsv* constants.
const std::vector<std::string>& integrationNames();

struct PreparedScene {
    shader::IsvFrame frame{};
    shader::CameraParams camera{};  // at the rendering resolution (supersampled)
    int width = 0, height = 0;      // rendering resolution: the image's times supersampling
    int supersampling = 1;
    float nearPlane = 0.05f;
    std::vector<shader::IsvParticle> particles;  // every particle medium's, in scene order
    GpuSurfaces surfaces;
    bool shadowMap = false;  // the opaque shadow map is needed (opaque shadows on and the scene has surfaces)
    bool vsm = false;        // the volumetric shadow map is needed (self-shadowing on and particles exist)
    bool chromatic = false;  // a medium's extinction differs per channel: RGB transmittance (coloured shadows)
};

// The scene's lights that ISV renders: its directional lights, then its point (and spot) lights, one pass each; the
// passes' images sum to the image lit by all of them.
int lightCount(const Scene& scene);

// Throws InputError for what ISV cannot render: more than kIsvMaxMedia particle media, a point light that its
// perspective maps cannot hold (inside or beside the particles), an unreadable OBJ. The frame is lit by light 0
// (black without a light); lightScene sets another.
PreparedScene prepareScene(const Scene& scene, const Settings& settings, const std::string& projectDir);

// Sets the frame's light to the scene's light `light` (as lightCount orders them; -1: none) with its light-space grids
// and which maps it needs; the particles, surfaces and camera are kept. Throws InputError as prepareScene.
void lightScene(PreparedScene& p, const Scene& scene, const Settings& settings, int light);

// The particle's view depth range is in front of the near plane (the others are culled, as in the thesis).
bool inFrontOfNearPlane(const PreparedScene& scene, const shader::IsvParticle& p);

// Back-to-front order of the particles: decreasing distance of the centre from the camera, ties by index (the GPU
// sort uses the same key).
std::vector<std::uint32_t> backToFront(const PreparedScene& scene);
// The sort key of a particle: its centre's distance from the camera as float bits (monotonic for non-negative floats).
std::uint32_t sortKey(const PreparedScene& scene, const shader::IsvParticle& p);

// Binds the light-space maps to the calling thread for the C++ definitions of isvVsmTexel and isvShadowTexel.
class MapScope {
public:
    MapScope(const std::vector<float>* vsm, const std::vector<float>* shadow);
    ~MapScope();
    MapScope(const MapScope&) = delete;
    MapScope& operator=(const MapScope&) = delete;

private:
    const std::vector<float>* previousVsm_;
    const std::vector<float>* previousShadow_;
};

// ---------------------------------------------------------------------------------------------------------------------
// The CPU model: each pass as the GPU runs it, per texel or pixel centre. `cancel` may be null.

// The opaque shadow map: per texel the distance along the light from the grid's plane to the first surface (FLT_MAX
// where there is none).
std::vector<float> shadowMapCpu(const PreparedScene& scene, int threads, const std::atomic<bool>* cancel);

// The volumetric shadow map's slabs: per slab j (between slices j and j + 1) and texel, the optical depth of every
// particle's part in it, per channel: kVsmChannels floats per texel (rgb, 0), as the GPU's chromatic variant stores
// them. slicesFromSlabs sums them front to back into slices (slice 0 is zero).
inline constexpr int kVsmChannels = 4;
std::vector<float> vsmSlabsCpu(const PreparedScene& scene, int threads, const std::atomic<bool>* cancel);
std::vector<float> slicesFromSlabs(const std::vector<float>& slabs, const shader::IsvLightSpace& grid);

// The opaque surfaces seen from the camera: per pixel (rgb radiance, distance to the surface or FLT_MAX).
std::vector<glm::vec4> surfacesCpu(const PreparedScene& scene, const std::vector<float>& vsm,
                                   const std::vector<float>& shadow, int threads, const std::atomic<bool>* cancel);

// The particles composited back to front over `background` (rgb, surface distance): per pixel (rgb, transmittance),
// the transmittance being the product of each fragment's mean over the channels (exact for grey media).
std::vector<glm::vec4> compositeCpu(const PreparedScene& scene, const std::vector<glm::vec4>& background,
                                    const std::vector<float>& vsm, const std::vector<float>& shadow,
                                    const std::vector<std::uint32_t>& order, int threads,
                                    const std::atomic<bool>* cancel);

}  // namespace tyndall::isv
