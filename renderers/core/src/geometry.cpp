// Scene geometry made concrete: built-in and OBJ meshes in world space, convex polyhedra clipped out of a large cube,
// the regular tetrahedra of particles, and the checks on polygons given by the user.
#include "tyndall/core/geometry.h"

#include "tyndall/core/error.h"

#include <tiny_obj_loader.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <limits>
#include <numbers>
#include <sstream>
#include <unordered_map>
#include <utility>

namespace tyndall {

namespace {

constexpr double kPi = std::numbers::pi;

template <typename... Args>
std::string concat(const Args&... args) {
    std::ostringstream out;
    (out << ... << args);
    return out.str();
}

bool isFinite(const Vec3& v) {
    return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z);
}

double maxAbs(const Vec3& v) {
    return std::max({std::abs(v.x), std::abs(v.y), std::abs(v.z)});
}

// Two points closer than this are the same point: a few thousand ulps of their coordinates, and at least 1 nm.
double sameTolerance(const Vec3& p) {
    return 1e-9 * std::max(1.0, maxAbs(p));
}

// Newell's normal: twice the area times the unit normal, for any planar polygon. Written as a sum of cross products
// about the centroid, which is the same vector and loses less precision far from the origin.
Vec3 newellVector(const std::vector<Vec3>& polygon) {
    Vec3 centroid(0.0);
    for (const Vec3& p : polygon)
        centroid += p;
    centroid /= static_cast<double>(polygon.size());
    Vec3 sum(0.0);
    for (std::size_t i = 0; i < polygon.size(); ++i) {
        sum += glm::cross(polygon[i] - centroid, polygon[(i + 1) % polygon.size()] - centroid);
    }
    return sum;
}

// ---------------------------------------------------------------------------------------------------------------------
// Meshes

// A mesh in its local frame, in double precision, before the transform is applied.
struct LocalMesh {
    std::vector<Vec3> positions;
    std::vector<Vec3> normals;  // one per position, or empty
    std::vector<glm::uvec3> triangles;

    std::uint32_t add(const Vec3& position, const Vec3& normal) {
        positions.push_back(position);
        normals.push_back(normal);
        return static_cast<std::uint32_t>(positions.size() - 1);
    }
};

// The square centred at `centre` with half-edges `u` and `v`, facing u x v: two triangles counter-clockwise seen from
// the front, with their own four vertices so that the normals stay flat.
void addSquare(LocalMesh& mesh, const Vec3& centre, const Vec3& u, const Vec3& v) {
    const Vec3 normal = glm::normalize(glm::cross(u, v));
    const std::uint32_t first = mesh.add(centre - u - v, normal);
    mesh.add(centre + u - v, normal);
    mesh.add(centre + u + v, normal);
    mesh.add(centre - u + v, normal);
    mesh.triangles.emplace_back(first, first + 1, first + 2);
    mesh.triangles.emplace_back(first, first + 2, first + 3);
}

LocalMesh unitPlane() {
    LocalMesh mesh;
    addSquare(mesh, Vec3(0.0), Vec3(0.0, 0.0, 0.5), Vec3(0.5, 0.0, 0.0));  // z x x = +y
    return mesh;
}

LocalMesh unitBox() {
    LocalMesh mesh;
    for (int axis = 0; axis < 3; ++axis) {
        for (double sign : {1.0, -1.0}) {
            Vec3 normal(0.0), u(0.0), v(0.0);
            normal[axis] = sign;
            u[(axis + 1) % 3] = 0.5;
            v[(axis + 2) % 3] = 0.5 * sign;  // u x v = normal
            addSquare(mesh, 0.5 * normal, u, v);
        }
    }
    return mesh;
}

// A UV sphere: `segments` around the y axis and segments / 2 rings from pole to pole. Each pole is a single vertex
// joined to the nearest ring by a fan, so that no triangle is degenerate.
LocalMesh unitSphere(int segments) {
    const int rings = segments / 2;
    LocalMesh mesh;
    const std::uint32_t north = mesh.add(Vec3(0.0, 1.0, 0.0), Vec3(0.0, 1.0, 0.0));
    for (int i = 1; i < rings; ++i) {
        const double theta = kPi * i / rings;  // from +y
        for (int j = 0; j < segments; ++j) {
            const double phi = 2.0 * kPi * j / segments;
            const Vec3 p(std::sin(theta) * std::cos(phi), std::cos(theta), std::sin(theta) * std::sin(phi));
            mesh.add(p, p);
        }
    }
    const std::uint32_t south = mesh.add(Vec3(0.0, -1.0, 0.0), Vec3(0.0, -1.0, 0.0));

    // Vertex j of ring i (1 <= i < rings). Going along j (d/dphi) then along i (d/dtheta) turns clockwise seen from
    // outside, so the counter-clockwise triangles below take the next j before the next i.
    const auto at = [segments](int i, int j) {
        return static_cast<std::uint32_t>(1 + (i - 1) * segments + j % segments);
    };
    for (int j = 0; j < segments; ++j)
        mesh.triangles.emplace_back(north, at(1, j + 1), at(1, j));
    for (int i = 1; i + 1 < rings; ++i) {
        for (int j = 0; j < segments; ++j) {
            mesh.triangles.emplace_back(at(i, j), at(i, j + 1), at(i + 1, j + 1));
            mesh.triangles.emplace_back(at(i, j), at(i + 1, j + 1), at(i + 1, j));
        }
    }
    for (int j = 0; j < segments; ++j)
        mesh.triangles.emplace_back(at(rings - 1, j), at(rings - 1, j + 1), south);
    return mesh;
}

std::string meshLabel(const Mesh& mesh) {
    return mesh.name.empty() ? std::string("mesh") : concat("mesh \"", mesh.name, "\"");
}

// The triangles of an OBJ file, triangulated; its normals when every corner of every face has one.
LocalMesh loadObj(const Mesh& mesh, const std::string& projectDir) {
    namespace fs = std::filesystem;
    if (mesh.file.empty()) throw InputError(meshLabel(mesh) + ": an OBJ mesh needs a file");
    fs::path path(mesh.file);
    if (path.is_relative() && !projectDir.empty()) path = fs::path(projectDir) / path;
    std::string label = concat(meshLabel(mesh), ": OBJ file \"", mesh.file, "\"");
    if (path.string() != mesh.file) label += concat(" (", path.string(), ")");

    std::error_code error;
    if (!fs::exists(path, error)) throw InputError(label + " does not exist");
    if (!fs::is_regular_file(path, error)) throw InputError(label + " is not a file");

    tinyobj::ObjReaderConfig config;
    config.triangulate = true;
    config.vertex_color = false;
    tinyobj::ObjReader reader;
    if (!reader.ParseFromFile(path.string(), config)) {
        std::string reason = reader.Error();
        while (!reason.empty() && std::isspace(static_cast<unsigned char>(reason.back()))) {
            reason.pop_back();
        }
        throw InputError(concat(label, " could not be read: ", reason.empty() ? "parse error" : reason));
    }

    const tinyobj::attrib_t& attrib = reader.GetAttrib();
    const std::size_t vertexCount = attrib.vertices.size() / 3;
    const auto position = [&attrib](int index) {
        const auto i = static_cast<std::size_t>(index) * 3;
        return Vec3(attrib.vertices[i], attrib.vertices[i + 1], attrib.vertices[i + 2]);
    };
    const auto normal = [&attrib](int index) {
        const auto i = static_cast<std::size_t>(index) * 3;
        return Vec3(attrib.normals[i], attrib.normals[i + 1], attrib.normals[i + 2]);
    };
    const auto usableNormal = [&](int index) {
        if (index < 0 || static_cast<std::size_t>(index) >= attrib.normals.size() / 3) return false;
        const Vec3 n = normal(index);
        return isFinite(n) && glm::length(n) > 0.0;
    };

    std::vector<tinyobj::index_t> corners;  // three per triangle
    bool everyCornerHasANormal = true;      // otherwise the normals are left out, and face normals are used
    for (const tinyobj::shape_t& shape : reader.GetShapes()) {
        std::size_t offset = 0;
        for (const auto faceSize : shape.mesh.num_face_vertices) {
            if (faceSize == 3) {
                for (std::size_t k = 0; k < 3; ++k) {
                    const tinyobj::index_t corner = shape.mesh.indices[offset + k];
                    if (corner.vertex_index < 0 || static_cast<std::size_t>(corner.vertex_index) >= vertexCount) {
                        throw InputError(concat(label, ": a face refers to vertex ", corner.vertex_index + 1,
                                                " but the file has ", vertexCount, " vertices"));
                    }
                    everyCornerHasANormal = everyCornerHasANormal && usableNormal(corner.normal_index);
                    corners.push_back(corner);
                }
            }
            offset += faceSize;
        }
    }
    if (corners.empty()) throw InputError(label + " has no triangles");

    LocalMesh local;
    std::vector<std::uint32_t> vertexOf(corners.size());
    if (everyCornerHasANormal) {
        // One vertex per distinct (position, normal) pair.
        std::unordered_map<std::uint64_t, std::uint32_t> index;
        for (std::size_t c = 0; c < corners.size(); ++c) {
            const auto key = (static_cast<std::uint64_t>(corners[c].vertex_index) << 32) |
                             static_cast<std::uint32_t>(corners[c].normal_index);
            const auto [it, inserted] = index.try_emplace(key, static_cast<std::uint32_t>(local.positions.size()));
            if (inserted) {
                local.add(position(corners[c].vertex_index), glm::normalize(normal(corners[c].normal_index)));
            }
            vertexOf[c] = it->second;
        }
    } else {
        for (std::size_t v = 0; v < vertexCount; ++v) {
            local.positions.push_back(position(static_cast<int>(v)));
        }
        for (std::size_t c = 0; c < corners.size(); ++c) {
            vertexOf[c] = static_cast<std::uint32_t>(corners[c].vertex_index);
        }
    }
    for (std::size_t c = 0; c < corners.size(); c += 3) {
        local.triangles.emplace_back(vertexOf[c], vertexOf[c + 1], vertexOf[c + 2]);
    }
    for (const Vec3& p : local.positions) {
        if (!isFinite(p)) throw InputError(label + " has a vertex with a non-finite coordinate");
    }
    return local;
}

// Positions by worldFromLocal, normals by its inverse transpose; a mirroring transform would turn the triangles
// clockwise seen from outside, so their winding is flipped back.
TriangleMesh toWorld(const LocalMesh& local, const Mesh& mesh) {
    const glm::dmat4 worldFromLocal = mesh.transform.worldFromLocal();
    const glm::dmat3 linear(worldFromLocal);
    const double determinant = glm::determinant(linear);
    if (!std::isfinite(determinant)) {
        throw InputError(concat(meshLabel(mesh), ": the transform's scale puts vertices beyond the limit of +-",
                                kMaxWorldCoordinate, " m for world coordinates"));
    }
    if (determinant == 0.0) {
        throw InputError(meshLabel(mesh) + ": the transform is singular (every scale component must be non-zero)");
    }
    const glm::dmat3 normalFromLocal = glm::transpose(glm::inverse(linear));

    TriangleMesh world;
    world.positions.reserve(local.positions.size());
    for (const Vec3& p : local.positions) {
        const Vec3 q(worldFromLocal * glm::dvec4(p, 1.0));
        if (!isFinite(q) || maxAbs(q) > kMaxWorldCoordinate) {
            throw InputError(concat(meshLabel(mesh), ": a vertex lands at ", q.x, ", ", q.y, ", ", q.z,
                                    " m, beyond the limit of +-", kMaxWorldCoordinate,
                                    " m for world coordinates (check the transform's scale and translate)"));
        }
        world.positions.emplace_back(q);
    }
    world.normals.reserve(local.normals.size());
    for (const Vec3& n : local.normals)
        world.normals.emplace_back(glm::normalize(normalFromLocal * n));
    world.triangles = local.triangles;
    if (determinant < 0.0) {
        for (glm::uvec3& triangle : world.triangles)
            std::swap(triangle.y, triangle.z);
    }
    return world;
}

// ---------------------------------------------------------------------------------------------------------------------
// Convex polyhedra

constexpr double kBigCube = 1e5;  // m, half-width of the cube the half-spaces are clipped out of

using Polygon = std::vector<Vec3>;

// -1 inside the half-space, 0 on its plane, +1 outside; "on" within a tolerance that grows with the magnitudes
// involved, since the vertices of the big cube are 1e5 m away.
int side(const Vec3& p, const HalfSpace& plane, double* distance = nullptr) {
    const double d = glm::dot(plane.normal, p) - plane.offset;
    if (distance) *distance = d;
    const double tolerance = 1e-9 * std::max({1.0, maxAbs(p), std::abs(plane.offset)});
    return d < -tolerance ? -1 : (d > tolerance ? 1 : 0);
}

// Consecutive vertices (the last and the first included) that are the same point are merged.
Polygon withoutRepeats(const Polygon& polygon) {
    Polygon out;
    for (const Vec3& p : polygon) {
        if (out.empty() || glm::distance(out.back(), p) > sameTolerance(p)) out.push_back(p);
    }
    while (out.size() > 1 && glm::distance(out.back(), out.front()) <= sameTolerance(out.front()))
        out.pop_back();
    return out;
}

// Sutherland-Hodgman: the part of `polygon` inside the half-space. The vertices on the plane and the points where
// edges cross it are appended to `onPlane`.
Polygon clip(const Polygon& polygon, const HalfSpace& plane, std::vector<Vec3>& onPlane) {
    const std::size_t n = polygon.size();
    std::vector<double> distance(n);
    std::vector<int> sides(n);
    for (std::size_t i = 0; i < n; ++i)
        sides[i] = side(polygon[i], plane, &distance[i]);

    Polygon out;
    for (std::size_t i = 0; i < n; ++i) {
        const std::size_t j = (i + 1) % n;
        if (sides[i] <= 0) out.push_back(polygon[i]);
        if (sides[i] == 0) onPlane.push_back(polygon[i]);
        if (sides[i] * sides[j] < 0) {
            // Interpolated from the inside end, so that the two faces sharing this edge get the very same point.
            const std::size_t in = sides[i] < 0 ? i : j;
            const std::size_t outside = sides[i] < 0 ? j : i;
            const double t = distance[in] / (distance[in] - distance[outside]);
            const Vec3 crossing = polygon[in] + t * (polygon[outside] - polygon[in]);
            out.push_back(crossing);
            onPlane.push_back(crossing);
        }
    }
    return withoutRepeats(out);
}

// The convex polygon through `points`, which lie on a plane with unit `normal`, counter-clockwise seen from the side
// the normal points to: the points sorted by angle around their centroid.
Polygon capPolygon(const std::vector<Vec3>& points, const Vec3& normal) {
    Polygon unique;
    for (const Vec3& p : points) {
        const bool seen = std::any_of(unique.begin(), unique.end(),
                                      [&p](const Vec3& q) { return glm::distance(p, q) <= sameTolerance(p); });
        if (!seen) unique.push_back(p);
    }
    if (unique.size() < 3) return {};

    Vec3 centroid(0.0);
    for (const Vec3& p : unique)
        centroid += p;
    centroid /= static_cast<double>(unique.size());
    const Vec3 u = glm::normalize(glm::cross(normal, std::abs(normal.x) < 0.9 ? Vec3(1, 0, 0) : Vec3(0, 1, 0)));
    const Vec3 v = glm::cross(normal, u);  // u x v = normal
    const auto angle = [&](const Vec3& p) { return std::atan2(glm::dot(p - centroid, v), glm::dot(p - centroid, u)); };
    std::sort(unique.begin(), unique.end(), [&](const Vec3& a, const Vec3& b) { return angle(a) < angle(b); });
    return unique;
}

std::vector<Polygon> cubeFaces(const Vec3& middle, double halfWidth) {
    std::vector<Polygon> faces;
    for (int axis = 0; axis < 3; ++axis) {
        for (double sign : {1.0, -1.0}) {
            Vec3 centre(middle), u(0.0), v(0.0);
            centre[axis] += sign * halfWidth;
            u[(axis + 1) % 3] = halfWidth;
            v[(axis + 2) % 3] = sign * halfWidth;  // u x v points outwards
            faces.push_back({centre - u - v, centre + u - v, centre + u + v, centre - u + v});
        }
    }
    return faces;
}

// The faces of the intersection of the half-spaces with `faces` (a closed convex solid), by clipping with one
// half-space after the other. Each plane that cuts the solid closes the cut with a cap polygon; a plane that only
// touches it, or repeats a plane already used, adds no face. Empty when the intersection is (nearly) empty.
std::vector<Polygon> clipSolid(std::vector<Polygon> faces, const std::vector<HalfSpace>& planes) {
    for (const HalfSpace& plane : planes) {
        std::vector<Vec3> onPlane;
        std::vector<Polygon> clipped;
        bool planeHasAFace = false;
        for (const Polygon& face : faces) {
            const bool inPlane =
                std::all_of(face.begin(), face.end(), [&](const Vec3& p) { return side(p, plane) == 0; });
            Polygon kept = clip(face, plane, onPlane);
            if (kept.size() < 3) continue;
            if (inPlane && glm::dot(newellVector(kept), plane.normal) > 0.0) planeHasAFace = true;
            clipped.push_back(std::move(kept));
        }
        if (!planeHasAFace) {
            Polygon cap = capPolygon(onPlane, plane.normal);
            if (cap.size() >= 3) clipped.push_back(std::move(cap));
        }
        faces = std::move(clipped);
        if (faces.empty()) break;
    }
    return faces;
}

}  // namespace

// ---------------------------------------------------------------------------------------------------------------------

TriangleMesh buildMesh(const Mesh& mesh, const std::string& projectDir) {
    switch (mesh.source) {
        case Mesh::Source::Plane:
            return toWorld(unitPlane(), mesh);
        case Mesh::Source::Box:
            return toWorld(unitBox(), mesh);
        case Mesh::Source::Sphere:
            if (mesh.subdivisions < 4 || mesh.subdivisions > 1024) {
                throw InputError(
                    concat(meshLabel(mesh), ": subdivisions must be in [4, 1024], got ", mesh.subdivisions));
            }
            return toWorld(unitSphere(mesh.subdivisions), mesh);
        case Mesh::Source::Obj:
            return toWorld(loadObj(mesh, projectDir), mesh);
    }
    contractFailure("mesh.source", __FILE__, __LINE__, "unknown mesh source");
}

ConvexPolyhedron makeConvexPolyhedron(const std::vector<HalfSpace>& planes) {
    if (planes.size() > kMaxPolyhedronPlanes) {
        throw InputError(concat("a polyhedron has at most ", kMaxPolyhedronPlanes, " planes, got ", planes.size()));
    }
    ConvexPolyhedron result;
    for (std::size_t i = 0; i < planes.size(); ++i) {
        const HalfSpace& plane = planes[i];
        if (!isFinite(plane.normal) || !std::isfinite(plane.offset)) {
            throw InputError(concat("plane ", i, " has a non-finite normal or offset"));
        }
        const double length = glm::length(plane.normal);
        if (!(length > 1e-12)) throw InputError(concat("plane ", i, " has a zero normal"));
        result.planes.push_back({plane.normal / length, plane.offset / length});
    }

    // The half-spaces are clipped out of a cube. It is placed at the planes' least-squares centre, the point nearest to
    // all of them (a box's centre; near any solid whose planes all touch it), sized from the planes' distances to it,
    // and grown until it holds the solid: so the clipping tolerances follow the solid's own size and place, and a box
    // 1e6 m away or 2e-6 m wide is found as well as one at the origin. Where that finds nothing bounded (redundant
    // planes far away can pull the centre off), the big cube around the origin decides, as it always did.
    Vec3 cubeCentre(0.0);
    double cubeHalfWidth = kBigCube;
    std::vector<Polygon> faces;
    const auto reachesCube = [&] {
        for (const Polygon& face : faces)
            for (const Vec3& p : face)
                if (maxAbs(p - cubeCentre) >= cubeHalfWidth * (1.0 - 1e-9)) return true;
        return false;
    };
    glm::dmat3 normalMatrix(0.0);
    Vec3 rhs(0.0);
    for (const HalfSpace& plane : result.planes) {
        normalMatrix += glm::outerProduct(plane.normal, plane.normal);
        rhs += plane.normal * plane.offset;
    }
    // Singular (|det| small against the trace's scale): the normals do not span space, so the region is unbounded.
    const double trace = normalMatrix[0][0] + normalMatrix[1][1] + normalMatrix[2][2];
    if (std::abs(glm::determinant(normalMatrix)) > 1e-9 * trace * trace * trace) {
        cubeCentre = glm::inverse(normalMatrix) * rhs;
        double farthest = 0.0;
        for (const HalfSpace& plane : result.planes)
            farthest = std::max(farthest, std::abs(glm::dot(plane.normal, cubeCentre) - plane.offset));
        if (maxAbs(cubeCentre) <= 2.0 * kMaxWorldCoordinate) {
            for (double h = std::max(2.0 * farthest, 1e-6 * std::max(1.0, maxAbs(cubeCentre))); h <= kBigCube;
                 h *= 8.0) {
                cubeHalfWidth = h;
                faces = clipSolid(cubeFaces(cubeCentre, cubeHalfWidth), result.planes);
                if (!faces.empty() && !reachesCube()) break;
            }
        }
    }
    if (faces.empty() || reachesCube()) {
        cubeCentre = Vec3(0.0);
        cubeHalfWidth = kBigCube;
        faces = clipSolid(cubeFaces(cubeCentre, cubeHalfWidth), result.planes);
    }
    if (faces.empty()) throw InputError("the half-spaces have an empty intersection (or only a point or a line)");
    if (reachesCube()) {
        throw InputError(
            concat("the half-spaces do not bound a finite region (or it is more than ", kBigCube, " m across)"));
    }
    Vec3 centroid(0.0);
    std::size_t vertexCount = 0;
    result.boundsMin = Vec3(std::numeric_limits<double>::infinity());
    result.boundsMax = Vec3(-std::numeric_limits<double>::infinity());
    for (const Polygon& face : faces) {
        for (const Vec3& p : face) {
            result.boundsMin = glm::min(result.boundsMin, p);
            result.boundsMax = glm::max(result.boundsMax, p);
            centroid += p;
            ++vertexCount;
        }
    }
    if (maxAbs(result.boundsMin) > kMaxWorldCoordinate || maxAbs(result.boundsMax) > kMaxWorldCoordinate) {
        throw InputError(concat("the solid reaches ", std::max(maxAbs(result.boundsMin), maxAbs(result.boundsMax)),
                                " m from the origin along an axis; world coordinates are limited to +-",
                                kMaxWorldCoordinate, " m"));
    }
    centroid /= static_cast<double>(vertexCount);

    // Signed tetrahedra from the centroid to a fan of each face.
    double volume = 0.0;
    for (const Polygon& face : faces) {
        for (std::size_t i = 1; i + 1 < face.size(); ++i) {
            volume += glm::dot(face[0] - centroid, glm::cross(face[i] - centroid, face[i + 1] - centroid)) / 6.0;
        }
    }
    // Flat, relative to its size: thinner than a billionth of its extent cubed. Smaller than the smallest size the
    // project format allows for a polygon, it is refused as such.
    const double extent = glm::length(result.boundsMax - result.boundsMin);
    if (!(volume > 1e-9 * extent * extent * extent)) {
        throw InputError(
            concat("the half-spaces bound a flat region (volume ", volume, " m^3 across ", extent, " m), not a solid"));
    }
    if (extent < kMinPolygonSize) {
        throw InputError(concat("the solid is ", extent,
                                " m across (its bounding box's diagonal); the smallest allowed is ", kMinPolygonSize,
                                " m"));
    }
    result.faces = std::move(faces);
    result.volume = volume;
    return result;
}

std::vector<HalfSpace> boxHalfSpaces(const OrientedBox& box) {
    const glm::dmat3 worldFromBox = box.worldFromBoxRotation();
    std::vector<HalfSpace> planes;
    for (int axis = 0; axis < 3; ++axis) {
        const Vec3 direction = glm::normalize(worldFromBox[axis]);
        const double centre = glm::dot(direction, box.centre);
        const double half = 0.5 * box.size[axis];
        planes.push_back({direction, centre + half});
        planes.push_back({-direction, -centre + half});
    }
    return planes;
}

std::array<Vec3, 4> tetrahedronVertices(const Particle& particle) {
    const double length = glm::length(particle.orientation);
    TY_CHECK(length > 0.0 && std::isfinite(length), "a particle's orientation must be a non-zero quaternion");
    const glm::dquat orientation = particle.orientation / length;
    const double s = particle.scale / std::sqrt(3.0);
    const std::array<Vec3, 4> canonical = {Vec3(1, 1, 1), Vec3(1, -1, -1), Vec3(-1, 1, -1), Vec3(-1, -1, 1)};
    std::array<Vec3, 4> vertices;
    for (std::size_t i = 0; i < 4; ++i)
        vertices[i] = particle.centre + orientation * (s * canonical[i]);
    return vertices;
}

// ---------------------------------------------------------------------------------------------------------------------
// Polygons

std::string polygonProblem(const std::vector<Vec3>& vertices) {
    const std::size_t n = vertices.size();
    if (n < 3) return concat("a polygon needs at least 3 vertices, got ", n);
    for (std::size_t i = 0; i < n; ++i) {
        if (!isFinite(vertices[i])) return concat("vertices[", i, "] has a non-finite coordinate");
    }

    Vec3 lo = vertices[0], hi = vertices[0], centroid(0.0);
    for (const Vec3& p : vertices) {
        lo = glm::min(lo, p);
        hi = glm::max(hi, p);
        centroid += p;
    }
    centroid /= static_cast<double>(n);
    if (maxAbs(lo) > kMaxWorldCoordinate || maxAbs(hi) > kMaxWorldCoordinate)
        return concat("a vertex is beyond the limit of +-", kMaxWorldCoordinate, " m for world coordinates");
    const double size = glm::distance(lo, hi);  // the bounding box's diagonal sets every tolerance
    if (!(size >= kMinPolygonSize))
        return concat("the polygon is ", size, " m across; the smallest allowed is ", kMinPolygonSize, " m");

    for (std::size_t i = 0; i < n; ++i) {
        const std::size_t j = (i + 1) % n;
        if (glm::distance(vertices[i], vertices[j]) <= 1e-9 * size) {
            if (j == 0)
                return "the last vertex repeats the first: do not repeat the first vertex, polygons close by "
                       "themselves";
            return concat("vertices[", i, "] and vertices[", j, "] are the same point");
        }
    }

    const Vec3 newell = newellVector(vertices);
    if (0.5 * glm::length(newell) < 1e-12 * size * size) {
        // Zero area with the vertices off a common line means that the signed areas cancel: the polygon crosses
        // itself like a bowtie.
        const Vec3 a = vertices[0];
        Vec3 b = a;
        for (const Vec3& p : vertices) {
            if (glm::distance(a, p) > glm::distance(a, b)) b = p;
        }
        const Vec3 line = glm::normalize(b - a);
        double offLine = 0.0;
        for (const Vec3& p : vertices)
            offLine = std::max(offLine, glm::length(glm::cross(line, p - a)));
        if (offLine <= 1e-9 * size) return "the polygon has zero area: its vertices are collinear";
        return "the polygon has zero net area: it crosses itself (like a bowtie) or is far from planar";
    }
    const Vec3 normal = glm::normalize(newell);

    const double planeTolerance = 1e-5 * size;
    for (std::size_t i = 0; i < n; ++i) {
        const double offPlane = std::abs(glm::dot(vertices[i] - centroid, normal));
        if (offPlane > planeTolerance) {
            return concat("the polygon is not planar: vertices[", i, "] is ", offPlane, " m off its plane (tolerance ",
                          planeTolerance, " m)");
        }
    }

    // Convex: every turn is to the left about the normal, none folds back, and together they make one full turn
    // (a pentagram turns left everywhere but twice around).
    constexpr double kAngleTolerance = 1e-6;  // radians
    double totalTurn = 0.0;
    for (std::size_t i = 0; i < n; ++i) {
        const Vec3 in = vertices[i] - vertices[(i + n - 1) % n];
        const Vec3 out = vertices[(i + 1) % n] - vertices[i];
        const double turn = std::atan2(glm::dot(glm::cross(in, out), normal), glm::dot(in, out));
        if (std::abs(turn) > kPi - kAngleTolerance) {
            return concat("the polygon is not convex: it folds back on itself at vertices[", i, "]");
        }
        if (turn < -kAngleTolerance) {
            return concat("the polygon is not convex: it turns the other way at vertices[", i, "]");
        }
        totalTurn += turn;
    }
    if (std::abs(totalTurn - 2.0 * kPi) > 1e-3) {
        return concat("the polygon is not convex: it winds ", std::lround(totalTurn / (2.0 * kPi)),
                      " times around its centre, crossing itself");
    }
    return "";
}

Vec3 polygonNormal(const std::vector<Vec3>& vertices) {
    TY_CHECK(vertices.size() >= 3, "a polygon needs at least 3 vertices");
    const Vec3 newell = newellVector(vertices);
    const double length = glm::length(newell);
    TY_CHECK(length > 0.0 && std::isfinite(length), "the polygon has no normal: its area is zero");
    return newell / length;
}

double polygonArea(const std::vector<Vec3>& vertices) {
    if (vertices.size() < 3) return 0.0;
    return 0.5 * glm::length(newellVector(vertices));
}

}  // namespace tyndall
