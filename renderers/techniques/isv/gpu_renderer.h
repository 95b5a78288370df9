// The ISV technique on Vulkan: compute passes for the opaque shadow map, the surfaces and the back-to-front sort, and
// graphics pipelines for the volumetric shadow map's slabs and the particles' proxies (a geometry shader builds each
// tetrahedron's projected-tetrahedron proxy, the fragment stage shades the ray's interval, blending composites). The
// pipelines are compiled on first use and kept. The same passes as the CPU model in prepared.h.
#pragma once

#include "isv/prepared.h"

#include "tyndall/core/error.h"
#include "tyndall/framework/technique.h"
#include "tyndall/gpu/context.h"

#include <memory>
#include <optional>
#include <string>
#include <vector>

namespace tyndall::isv {

struct GpuTimings {
    double totalMs = 0.0;         // GPU time of every pass
    double shadowMapMs = 0.0;     // the opaque shadow map
    double vsmMs = 0.0;           // the volumetric shadow map (slabs and their sum)
    double surfacesMs = 0.0;      // the surfaces seen by the camera
    double sortMs = 0.0;          // keys and the bitonic sort
    double particlesMs = 0.0;     // the particles' proxies, shading and blending
    double longestSliceMs = 0.0;  // the longest single submission
    double compileSeconds = 0.0;  // pipelines compiled by this render
};

struct GpuOutput {
    std::vector<glm::vec4> pixels;  // per pixel of the rendering resolution: (rgb, transmittance)
    std::string deviceName;
    GpuTimings timings;
    bool meshProxies = false;  // the proxies came from the mesh shader
};

// What keeps the scene from rendering on `device` as configured, as an InputError naming the field to change (the
// particle count, a map's resolution, the supersampling) and what the device allows; nullopt when it fits. The
// storage buffers and render targets the GPU passes would allocate are checked against the device's limits.
std::optional<InputError> deviceLimitProblem(const PreparedScene& scene, const gpu::DeviceInfo& device);

class GpuRenderer {
public:
    GpuRenderer();
    ~GpuRenderer();
    GpuRenderer(const GpuRenderer&) = delete;
    GpuRenderer& operator=(const GpuRenderer&) = delete;

    // Throws InputError (field `proxies`) when `proxies` asks for a mesh shader the device does not have.
    GpuOutput render(const PreparedScene& scene, const RenderCallbacks& callbacks, Proxies proxies = Proxies::Auto);

private:
    struct Impl;
    std::unique_ptr<Impl> impl_;
};

}  // namespace tyndall::isv
