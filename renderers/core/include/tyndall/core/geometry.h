// Scene geometry made concrete: meshes in world space, convex media as polyhedra, particles as tetrahedra, and the
// checks that polygons from the user are planar and convex.
#pragma once

#include "tyndall/core/scene.h"

#include <array>
#include <string>
#include <vector>

namespace tyndall {

// Limits that keep every renderer in finite numbers (the reference and the GPU techniques work in float, and Embree
// asserts on non-finite bounds): every world-space coordinate (positions, vertices, box corners, particles, mesh
// vertices after their transform) is within +-kMaxWorldCoordinate, and a user polygon is at least kMinPolygonSize
// across. docs/conventions.md lists them.
inline constexpr double kMaxWorldCoordinate = 1e8;  // m
inline constexpr double kMinPolygonSize = 1e-6;     // m, the diagonal of the polygon's bounding box
// Radiometric values (intensity W/sr, irradiance W/m^2, radiance W/(m^2 sr)) and coefficients (sigma_s, sigma_a,
// extinction, 1/m) are bounded too, so that products of them with the geometry's factors (1/r^2 over the world's
// extent, path throughputs) stay finite in float: the sun's radiance is about 2e7 W/(m^2 sr), a mean free path of
// 1 micrometre is 1e6 /m.
inline constexpr double kMaxRadiometric = 1e15;
inline constexpr double kMaxCoefficient = 1e6;  // 1/m
// A convex polyhedron medium has at most this many planes: clipping costs O(planes^2) or more.
inline constexpr std::size_t kMaxPolyhedronPlanes = 1024;

// The world-space triangles of a mesh (built-in plane/box/sphere, or an OBJ file resolved against projectDir).
// Throws InputError naming the mesh (field `meshes[i]` is the caller's to add) for a missing or empty OBJ file, bad
// face indices, a singular transform or a vertex beyond kMaxWorldCoordinate.
TriangleMesh buildMesh(const Mesh& mesh, const std::string& projectDir);

// A bounded convex polyhedron as the intersection of half-spaces: its faces as convex polygons (counter-clockwise seen
// from outside). Throws InputError when the intersection is empty, flat or unbounded.
struct ConvexPolyhedron {
    std::vector<HalfSpace> planes;            // normalised
    std::vector<std::vector<Vec3>> faces;     // one polygon per plane that bounds the solid
    Vec3 boundsMin{0.0}, boundsMax{0.0};
    double volume = 0.0;                      // m^3
};
ConvexPolyhedron makeConvexPolyhedron(const std::vector<HalfSpace>& planes);
// The six half-spaces of an oriented box.
std::vector<HalfSpace> boxHalfSpaces(const OrientedBox& box);

// The four vertices of a particle's regular tetrahedron, each at distance `scale` from the centre.
std::array<Vec3, 4> tetrahedronVertices(const Particle& particle);

// Checks for a user polygon (area lights, gobos): >= 3 vertices, non-zero area, planar within a relative tolerance,
// convex and without repeated vertices. Returns "" when valid, otherwise the reason in words.
std::string polygonProblem(const std::vector<Vec3>& vertices);
// Unit normal by the right-hand rule (counter-clockwise seen from the front) and area of a valid polygon.
Vec3 polygonNormal(const std::vector<Vec3>& vertices);
double polygonArea(const std::vector<Vec3>& vertices);

}  // namespace tyndall
