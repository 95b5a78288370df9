// The scene's surfaces as the GPU renderers see them (shaders/shared/surface.h and bvh.h): one shading record per
// triangle, the materials, and the BVH over every mesh. Built once per render by every GPU technique's CPU side.
#pragma once

#include "shared/bsdf.h"
#include "shared/camera.h"
#include "shared/surface.h"
#include "tyndall/core/scene.h"
#include "tyndall/gpu/bvh.h"
#include "tyndall/image/image.h"

#include <string>
#include <vector>

namespace tyndall {

struct GpuSurfaces {
    std::vector<shader::SurfaceTriangle> triangles;  // indexed by BvhTriangle::id; never empty (a dummy when no mesh)
    std::size_t triangleCount = 0;                   // the scene's triangles (0: `triangles` holds only the dummy)
    std::vector<shader::MaterialParams> materials;   // in Scene::materials order; never empty
    gpu::Bvh bvh;
    glm::vec3 boundsMin{0.0f}, boundsMax{0.0f};  // m, of every triangle (min > max when there is none)
    float rayOffset = 1e-4f;                     // m, offset of rays leaving surfaces: 1e-4 of the scene's size
    bool anyGgx = false;                         // a material is GGX (which may read the mesh's tangent)

    // The compile-time variants of shared/surface.h that these surfaces allow (GLSL #define lines, "" for none):
    // TY_SURFACE_NO_TANGENTS when every material is diffuse.
    std::string shaderDefines() const;
};

// Throws InputError for a mesh whose material is unknown or whose file cannot be read.
GpuSurfaces prepareGpuSurfaces(const Scene& scene, const std::string& projectDir);

// A denoiser's guides (tyndall/denoise.h) from each pixel's centre ray: the distance to the first surface ("Z",
// infinite where there is none) and its shading normal ("N.X", "N.Y", "N.Z", zero where there is none).
struct SurfaceGuides {
    Image depth;
    Image normal;
};
SurfaceGuides centreRayGuides(const GpuSurfaces& surfaces, const shader::CameraParams& camera, int width, int height);

}  // namespace tyndall
