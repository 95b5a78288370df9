// Primary visibility by rasterisation (issue 31): the closest hits of the camera rays of a regular grid of S x S
// samples per pixel, drawn as a G-buffer by a graphics pipeline (shaders/primary/) instead of one BVH traversal per
// ray in a compute kernel. Kernels compiled with TY_PRIMARY_HITS read the records through primaryIntersect
// (shaders/shared/primary_hits.h, which documents the record); jittered rays and samples the raster could not resolve
// exactly are still traced. Written once for every GPU technique whose camera samples sit on such a grid (LTSD's
// analytic pass, Pegoraro); docs/architecture.md says which use it and why the jittered ones do not.
#pragma once

#include "shared/camera.h"
#include "tyndall/gpu/context.h"
#include "tyndall/gpu/resources.h"

#include <cstdint>
#include <memory>
#include <string>

namespace tyndall {

namespace gpu {
class GraphicsPipeline;
class RenderTarget;
}

// Why `device` cannot rasterise the closest hits of a grid of samplesWide x samplesHigh samples over `triangles`
// triangles (no graphics queue, a grid beyond its framebuffer or storage-buffer limits, triangle ids beyond a float's
// exact integers); empty when it can.
std::string rasterPrimaryUnsupported(const gpu::DeviceInfo& device, std::uint64_t samplesWide,
                                     std::uint64_t samplesHigh, std::uint64_t triangles);

struct PrimaryHits {
    // One vec4 per grid sample, kept by the RasterPrimaryHits until its next render; null when the kernel must trace.
    const gpu::Buffer* records = nullptr;
    // "raster", or "traced: <why>" (the images' metadata key "primaryVisibility", docs/conventions.md).
    std::string visibility;
    double gpuMs = 0.0;
    double compileSeconds = 0.0;  // building the pipeline (0 when it was built before)
};

class RasterPrimaryHits {
public:
    explicit RasterPrimaryHits(gpu::Context& context);
    ~RasterPrimaryHits();
    RasterPrimaryHits(const RasterPrimaryHits&) = delete;
    RasterPrimaryHits& operator=(const RasterPrimaryHits&) = delete;

    // The closest hits of the camera's grid of S x S samples per pixel over the BVH's triangles, as uploaded for the
    // kernels (bvhNodes, bvhTriangles: shared/bvh.h's layout, BvhTriangle structs; `triangles` of them). Where the
    // device cannot (rasterPrimaryUnsupported, or a render target it refuses), or the environment says
    // TYNDALL_RASTER_PRIMARY=0 (benchmarks compare both), no records and the reason: the caller's kernel traces. One
    // submission, waited for.
    PrimaryHits render(const gpu::Buffer& bvhNodes, const gpu::Buffer& bvhTriangles, std::uint64_t triangles,
                       const shader::CameraParams& camera, int samplesPerSide);

private:
    gpu::Context& context_;
    std::unique_ptr<gpu::GraphicsPipeline> pipeline_;
    // Kept from render to render (gpu::keptBuffer's reason).
    std::unique_ptr<gpu::RenderTarget> recordTarget_, depthTarget_;
    std::unique_ptr<gpu::Buffer> records_;
};

}  // namespace tyndall
