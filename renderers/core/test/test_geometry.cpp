// Tests of scene geometry: built-in and OBJ meshes, convex polyhedra from half-spaces, particle tetrahedra and the
// checks on user polygons.
#include "tyndall/core/geometry.h"

#include "tyndall/core/error.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>
#include <string>
#include <utility>
#include <vector>

namespace tyndall {
namespace {

constexpr double kPi = std::numbers::pi;
const std::string kDataDir = std::string(TYNDALL_SOURCE_DIR) + "/tests/data";

// ---------------------------------------------------------------------------------------------------------------------
// Helpers

Vec3 corner(const TriangleMesh& mesh, const glm::uvec3& triangle, int k) {
    return Vec3(mesh.positions[triangle[k]]);
}

// Unnormalised normal by the winding (counter-clockwise seen from the side it points to).
Vec3 windingNormal(const TriangleMesh& mesh, const glm::uvec3& triangle) {
    const Vec3 a = corner(mesh, triangle, 0), b = corner(mesh, triangle, 1), c = corner(mesh, triangle, 2);
    return glm::cross(b - a, c - a);
}

Vec3 vertexCentroid(const TriangleMesh& mesh) {
    Vec3 sum(0.0);
    for (const glm::vec3& p : mesh.positions)
        sum += Vec3(p);
    return sum / static_cast<double>(mesh.positions.size());
}

// Volume enclosed by a closed mesh, positive when its triangles face outwards.
double signedVolume(const TriangleMesh& mesh) {
    double volume = 0.0;
    for (const glm::uvec3& t : mesh.triangles) {
        volume += glm::dot(corner(mesh, t, 0), glm::cross(corner(mesh, t, 1), corner(mesh, t, 2))) / 6.0;
    }
    return volume;
}

// For a convex closed mesh: every triangle faces away from the centre, and the vertex normals agree with it.
void expectFacesOutward(const TriangleMesh& mesh) {
    const Vec3 centre = vertexCentroid(mesh);
    double sum = 0.0;
    for (const glm::uvec3& t : mesh.triangles) {
        const Vec3 n = windingNormal(mesh, t);
        const Vec3 middle = (corner(mesh, t, 0) + corner(mesh, t, 1) + corner(mesh, t, 2)) / 3.0;
        const double facing = glm::dot(n, middle - centre);
        EXPECT_GT(facing, 0.0) << "triangle " << t.x << " " << t.y << " " << t.z;
        sum += facing;
        if (!mesh.normals.empty()) {
            for (int k = 0; k < 3; ++k)
                EXPECT_GT(glm::dot(Vec3(mesh.normals[t[k]]), n), 0.0);
        }
    }
    EXPECT_GT(sum, 0.0);
}

void expectUnitNormals(const TriangleMesh& mesh) {
    for (const glm::vec3& n : mesh.normals)
        EXPECT_NEAR(glm::length(n), 1.0f, 1e-5f);
}

Mesh sphere(int subdivisions) {
    Mesh mesh;
    mesh.source = Mesh::Source::Sphere;
    mesh.subdivisions = subdivisions;
    return mesh;
}

Mesh builtIn(Mesh::Source source) {
    Mesh mesh;
    mesh.source = source;
    return mesh;
}

Mesh obj(const std::string& file) {
    Mesh mesh;
    mesh.name = "model";
    mesh.source = Mesh::Source::Obj;
    mesh.file = file;
    return mesh;
}

// The message of the InputError that `f` throws, or a failure.
template <typename F>
std::string inputErrorOf(F&& f) {
    try {
        f();
    } catch (const InputError& e) {
        return e.what();
    }
    ADD_FAILURE() << "no InputError was thrown";
    return "";
}

double maxAbsOf(const Vec3& v) {
    return std::max({std::abs(v.x), std::abs(v.y), std::abs(v.z)});
}

bool contains(const std::string& text, const std::string& part) {
    return text.find(part) != std::string::npos;
}

// ---------------------------------------------------------------------------------------------------------------------
// Built-in meshes

TEST(Mesh, PlaneIsTwoTrianglesFacingUp) {
    const TriangleMesh plane = buildMesh(builtIn(Mesh::Source::Plane), "");
    ASSERT_EQ(plane.triangles.size(), 2u);
    ASSERT_EQ(plane.normals.size(), plane.positions.size());
    double area = 0.0;
    for (const glm::uvec3& t : plane.triangles) {
        const Vec3 n = windingNormal(plane, t);
        EXPECT_GT(n.y, 0.0);
        EXPECT_NEAR(glm::length(glm::cross(n, Vec3(0, 1, 0))), 0.0, 1e-12);
        area += 0.5 * glm::length(n);
    }
    EXPECT_NEAR(area, 1.0, 1e-12);
    for (const glm::vec3& p : plane.positions) {
        EXPECT_EQ(p.y, 0.0f);
        EXPECT_EQ(std::abs(p.x), 0.5f);
        EXPECT_EQ(std::abs(p.z), 0.5f);
    }
    for (const glm::vec3& n : plane.normals)
        EXPECT_EQ(n, glm::vec3(0, 1, 0));
}

TEST(Mesh, BoxHasTwelveOutwardTrianglesWithFlatNormals) {
    const TriangleMesh box = buildMesh(builtIn(Mesh::Source::Box), "");
    EXPECT_EQ(box.triangles.size(), 12u);
    EXPECT_EQ(box.positions.size(), 24u);
    ASSERT_EQ(box.normals.size(), 24u);
    EXPECT_NEAR(signedVolume(box), 1.0, 1e-12);
    expectFacesOutward(box);
    for (const glm::uvec3& t : box.triangles) {
        const Vec3 n = glm::normalize(windingNormal(box, t));
        for (int k = 0; k < 3; ++k)
            EXPECT_NEAR(glm::distance(Vec3(box.normals[t[k]]), n), 0.0, 1e-6);
    }
    for (const glm::vec3& p : box.positions) {
        EXPECT_EQ(glm::abs(p), glm::vec3(0.5f));
    }
}

TEST(Mesh, SphereIsClosedFacesOutwardAndHasNoDegenerateTriangles) {
    const TriangleMesh mesh = buildMesh(sphere(32), "");
    constexpr std::size_t segments = 32, rings = 16;
    EXPECT_EQ(mesh.triangles.size(), 2 * segments * (rings - 1));
    EXPECT_EQ(mesh.positions.size(), 2 + segments * (rings - 1));
    ASSERT_EQ(mesh.normals.size(), mesh.positions.size());
    expectFacesOutward(mesh);
    expectUnitNormals(mesh);
    for (std::size_t i = 0; i < mesh.positions.size(); ++i) {
        EXPECT_NEAR(glm::length(mesh.positions[i]), 1.0f, 1e-6f);
        EXPECT_NEAR(glm::distance(mesh.positions[i], mesh.normals[i]), 0.0f, 1e-6f);  // smooth: normal = position
    }
    for (const glm::uvec3& t : mesh.triangles)
        EXPECT_GT(glm::length(windingNormal(mesh, t)), 1e-4);

    // Closed: every edge is used once in each direction.
    std::vector<std::pair<unsigned, unsigned>> edges, reversed;
    for (const glm::uvec3& t : mesh.triangles) {
        for (int k = 0; k < 3; ++k) {
            edges.emplace_back(t[k], t[(k + 1) % 3]);
            reversed.emplace_back(t[(k + 1) % 3], t[k]);
        }
    }
    std::sort(edges.begin(), edges.end());
    std::sort(reversed.begin(), reversed.end());
    EXPECT_EQ(std::adjacent_find(edges.begin(), edges.end()), edges.end());
    EXPECT_EQ(edges, reversed);
}

TEST(Mesh, SphereVolumeApproachesFourThirdsPi) {
    // The sphere is inscribed, so its volume falls short, by a relative error that shrinks like 1 / subdivisions^2.
    const double exact = 4.0 / 3.0 * kPi;
    std::vector<double> errors;
    for (int subdivisions : {4, 8, 32, 128}) {
        const double volume = signedVolume(buildMesh(sphere(subdivisions), ""));
        EXPECT_GT(volume, 0.0);
        errors.push_back((exact - volume) / exact);
        EXPECT_GT(errors.back(), 0.0) << subdivisions;
    }
    EXPECT_NEAR(errors[0], 1.0 - (4.0 / 3.0) / exact, 1e-6);  // 4 subdivisions: an octahedron
    EXPECT_LT(errors[1], errors[0]);
    EXPECT_LT(errors[2], errors[1]);
    EXPECT_NEAR(errors[2] / errors[3], 16.0, 1.0);
    EXPECT_LT(errors[3], 2e-3);
}

TEST(Mesh, OddSphereSubdivisionsWork) {
    const TriangleMesh mesh = buildMesh(sphere(7), "");  // 7 segments, 3 rings
    EXPECT_EQ(mesh.triangles.size(), 2u * 7u * 2u);
    expectFacesOutward(mesh);
}

TEST(Mesh, SphereSubdivisionsOutOfRangeAreRefused) {
    EXPECT_TRUE(contains(inputErrorOf([] { buildMesh(sphere(3), ""); }), "subdivisions"));
    EXPECT_THROW(buildMesh(sphere(2000), ""), InputError);
}

// ---------------------------------------------------------------------------------------------------------------------
// Transforms

TEST(Mesh, TranslationMovesEveryVertex) {
    Mesh moved = builtIn(Mesh::Source::Box);
    moved.transform.translate = Vec3(1.0, -2.0, 3.0);
    const TriangleMesh a = buildMesh(builtIn(Mesh::Source::Box), "");
    const TriangleMesh b = buildMesh(moved, "");
    ASSERT_EQ(a.positions.size(), b.positions.size());
    for (std::size_t i = 0; i < a.positions.size(); ++i) {
        EXPECT_NEAR(glm::distance(Vec3(b.positions[i]), Vec3(a.positions[i]) + moved.transform.translate), 0.0, 1e-6);
        EXPECT_EQ(a.normals[i], b.normals[i]);
    }
    EXPECT_EQ(a.triangles, b.triangles);
    EXPECT_NEAR(signedVolume(b), 1.0, 1e-5);
}

TEST(Mesh, RotationTurnsPositionsAndNormals) {
    // 90 degrees about x takes +y to +z and +z to -y: the plane becomes the xy plane facing +z.
    Mesh plane = builtIn(Mesh::Source::Plane);
    plane.transform.rotate = Vec3(90.0, 0.0, 0.0);
    const TriangleMesh mesh = buildMesh(plane, "");
    for (const glm::vec3& p : mesh.positions)
        EXPECT_NEAR(p.z, 0.0f, 1e-6f);
    for (const glm::vec3& n : mesh.normals)
        EXPECT_NEAR(glm::distance(n, glm::vec3(0, 0, 1)), 0.0f, 1e-6f);
    for (const glm::uvec3& t : mesh.triangles)
        EXPECT_GT(windingNormal(mesh, t).z, 0.0);

    // 90 degrees about y takes +x to -z.
    Mesh box = builtIn(Mesh::Source::Box);
    box.transform.rotate = Vec3(0.0, 90.0, 0.0);
    box.transform.scale = Vec3(2.0, 1.0, 1.0);
    const TriangleMesh turned = buildMesh(box, "");
    for (const glm::vec3& p : turned.positions) {
        EXPECT_NEAR(std::abs(p.z), 1.0f, 1e-6f);
        EXPECT_NEAR(std::abs(p.x), 0.5f, 1e-6f);
    }
    expectFacesOutward(turned);
    EXPECT_NEAR(signedVolume(turned), 2.0, 1e-5);
}

TEST(Mesh, NonUniformScaleTransformsNormalsByTheInverseTranspose) {
    Mesh ellipsoid = sphere(64);
    const Vec3 axes(2.0, 1.0, 0.5);
    ellipsoid.transform.scale = axes;
    const TriangleMesh mesh = buildMesh(ellipsoid, "");
    expectFacesOutward(mesh);
    expectUnitNormals(mesh);
    EXPECT_NEAR(signedVolume(mesh), signedVolume(buildMesh(sphere(64), "")), 1e-5);  // the scale's determinant is 1
    for (std::size_t i = 0; i < mesh.positions.size(); ++i) {
        const Vec3 p(mesh.positions[i]);
        const Vec3 expected = glm::normalize(p / (axes * axes));  // gradient of the ellipsoid's implicit function
        EXPECT_NEAR(glm::distance(Vec3(mesh.normals[i]), expected), 0.0, 1e-5);
    }
}

TEST(Mesh, MirroringKeepsTrianglesOutward) {
    for (const Vec3& scale : {Vec3(-1.0, 1.0, 1.0), Vec3(1.0, -2.0, 1.0), Vec3(-1.0, -1.0, -1.0)}) {
        for (Mesh mesh : {builtIn(Mesh::Source::Box), sphere(16)}) {
            mesh.transform.scale = scale;
            mesh.transform.rotate = Vec3(10.0, 20.0, 30.0);
            const TriangleMesh world = buildMesh(mesh, "");
            const double det = scale.x * scale.y * scale.z;
            const double unitVolume =
                signedVolume(buildMesh(mesh.source == Mesh::Source::Box ? builtIn(Mesh::Source::Box) : sphere(16), ""));
            EXPECT_NEAR(signedVolume(world), std::abs(det) * unitVolume, 1e-5);
            expectFacesOutward(world);
            expectUnitNormals(world);
        }
    }
    Mesh plane = builtIn(Mesh::Source::Plane);
    plane.transform.scale = Vec3(-1.0, 1.0, 1.0);
    const TriangleMesh mirrored = buildMesh(plane, "");
    for (const glm::uvec3& t : mirrored.triangles)
        EXPECT_GT(windingNormal(mirrored, t).y, 0.0);
}

TEST(Mesh, SingularTransformIsRefused) {
    Mesh box = builtIn(Mesh::Source::Box);
    box.transform.scale = Vec3(1.0, 0.0, 1.0);
    EXPECT_THROW(buildMesh(box, ""), InputError);
}

// ---------------------------------------------------------------------------------------------------------------------
// OBJ files

TEST(Mesh, ObjIsLoadedRelativeToTheProjectFolder) {
    const TriangleMesh mesh = buildMesh(obj("tetra.obj"), kDataDir);
    EXPECT_EQ(mesh.positions.size(), 4u);
    EXPECT_EQ(mesh.triangles.size(), 4u);
    EXPECT_TRUE(mesh.normals.empty());
    EXPECT_NEAR(signedVolume(mesh), 1.0 / 6.0, 1e-7);
    expectFacesOutward(mesh);
}

TEST(Mesh, ObjWithAnAbsolutePathIgnoresTheProjectFolder) {
    Mesh mesh = obj(kDataDir + "/tetra.obj");
    mesh.transform.translate = Vec3(0.0, 10.0, 0.0);
    mesh.transform.scale = Vec3(2.0);
    const TriangleMesh world = buildMesh(mesh, "/nonexistent/folder");
    EXPECT_NEAR(signedVolume(world), 8.0 / 6.0, 1e-5);
    for (const glm::vec3& p : world.positions)
        EXPECT_GE(p.y, 10.0f);
}

TEST(Mesh, ObjNormalsAreUsedAndTransformed) {
    Mesh mesh = obj("quad_with_normals.obj");
    const TriangleMesh quad = buildMesh(mesh, kDataDir);
    EXPECT_EQ(quad.triangles.size(), 2u);  // the quad is triangulated
    ASSERT_EQ(quad.normals.size(), quad.positions.size());
    for (const glm::vec3& n : quad.normals)
        EXPECT_EQ(n, glm::vec3(0, 1, 0));
    for (const glm::uvec3& t : quad.triangles)
        EXPECT_GT(windingNormal(quad, t).y, 0.0);

    mesh.transform.rotate = Vec3(90.0, 0.0, 0.0);
    const TriangleMesh turned = buildMesh(mesh, kDataDir);
    for (const glm::vec3& n : turned.normals)
        EXPECT_NEAR(glm::distance(n, glm::vec3(0, 0, 1)), 0.0f, 1e-6f);
}

TEST(Mesh, MissingObjIsRefusedNamingTheFile) {
    const std::string message = inputErrorOf([] { buildMesh(obj("no_such_file.obj"), kDataDir); });
    EXPECT_TRUE(contains(message, "no_such_file.obj")) << message;
    EXPECT_TRUE(contains(message, "does not exist")) << message;
    EXPECT_TRUE(contains(message, "model")) << message;
}

TEST(Mesh, ObjWithoutTrianglesIsRefused) {
    const std::string message = inputErrorOf([] { buildMesh(obj("empty.obj"), kDataDir); });
    EXPECT_TRUE(contains(message, "empty.obj")) << message;
    EXPECT_TRUE(contains(message, "no triangles")) << message;
}

TEST(Mesh, ObjWithBadFacesIsRefused) {
    const std::string outOfRange = inputErrorOf([] { buildMesh(obj("bad_face_index.obj"), kDataDir); });
    EXPECT_TRUE(contains(outOfRange, "bad_face_index.obj")) << outOfRange;
    EXPECT_TRUE(contains(outOfRange, "vertex 9")) << outOfRange;
    const std::string parseError = inputErrorOf([] { buildMesh(obj("zero_face_index.obj"), kDataDir); });
    EXPECT_TRUE(contains(parseError, "zero_face_index.obj")) << parseError;
    EXPECT_TRUE(contains(parseError, "could not be read")) << parseError;
}

// ---------------------------------------------------------------------------------------------------------------------
// Convex polyhedra

Vec3 faceCentroid(const std::vector<Vec3>& face) {
    Vec3 sum(0.0);
    for (const Vec3& p : face)
        sum += p;
    return sum / static_cast<double>(face.size());
}

// Every face is a valid convex polygon lying on one of the planes, facing out of the solid.
void expectWellFormed(const ConvexPolyhedron& solid) {
    Vec3 centre(0.0);
    for (const auto& face : solid.faces)
        centre += faceCentroid(face);
    centre /= static_cast<double>(solid.faces.size());
    for (const auto& face : solid.faces) {
        EXPECT_EQ(polygonProblem(face), "");
        const Vec3 n = polygonNormal(face);
        EXPECT_GT(glm::dot(n, faceCentroid(face) - centre), 0.0);
        const bool onAPlane = std::any_of(solid.planes.begin(), solid.planes.end(), [&](const HalfSpace& plane) {
            return glm::dot(plane.normal, n) > 1.0 - 1e-9 && std::all_of(face.begin(), face.end(), [&](const Vec3& p) {
                       return std::abs(glm::dot(plane.normal, p) - plane.offset) < 1e-7;
                   });
        });
        EXPECT_TRUE(onAPlane);
        for (const Vec3& p : face) {
            for (const HalfSpace& plane : solid.planes)
                EXPECT_LE(glm::dot(plane.normal, p) - plane.offset, 1e-7);
            EXPECT_TRUE(glm::all(glm::greaterThanEqual(p, solid.boundsMin)));
            EXPECT_TRUE(glm::all(glm::lessThanEqual(p, solid.boundsMax)));
        }
    }
}

std::vector<HalfSpace> unitTetrahedronPlanes() {
    return {{Vec3(-1, 0, 0), 0.0}, {Vec3(0, -1, 0), 0.0}, {Vec3(0, 0, -1), 0.0}, {Vec3(1, 1, 1), 1.0}};
}

TEST(Polyhedron, FromABoxsHalfSpacesHasTheBoxVolumeAndSixFaces) {
    OrientedBox box;
    box.centre = Vec3(5.0, -2.0, 1.0);
    box.size = Vec3(1.0, 2.0, 3.0);
    box.rotate = Vec3(30.0, 45.0, 60.0);
    const ConvexPolyhedron solid = makeConvexPolyhedron(boxHalfSpaces(box));
    EXPECT_NEAR(solid.volume, 6.0, 1e-8);
    ASSERT_EQ(solid.faces.size(), 6u);
    for (const auto& face : solid.faces)
        EXPECT_EQ(face.size(), 4u);
    expectWellFormed(solid);

    // The bounds are those of the eight corners.
    const glm::dmat3 worldFromBox = box.worldFromBoxRotation();
    Vec3 lo(1e30), hi(-1e30);
    for (int i = 0; i < 8; ++i) {
        const Vec3 local((i & 1) ? 0.5 : -0.5, (i & 2) ? 0.5 : -0.5, (i & 4) ? 0.5 : -0.5);
        const Vec3 p = box.centre + worldFromBox * (local * box.size);
        lo = glm::min(lo, p);
        hi = glm::max(hi, p);
    }
    EXPECT_NEAR(glm::distance(solid.boundsMin, lo), 0.0, 1e-8);
    EXPECT_NEAR(glm::distance(solid.boundsMax, hi), 0.0, 1e-8);
}

// Issue 34: a box far from the origin, within the world's +-1e8 m, was refused as an "empty intersection" (the solid
// was looked for within 1e5 m of the origin only).
TEST(Polyhedron, ABoxFarFromTheOriginWithinTheWorldIsFound) {
    for (const Vec3& centre : {Vec3(0.0, 1.0, -1e6), Vec3(3e7, -2e7, 9e7), Vec3(-9.9e7, 0.0, 0.0)}) {
        OrientedBox box;
        box.centre = centre;
        box.size = Vec3(2.0, 1.0, 4.0);
        box.rotate = Vec3(10.0, 20.0, 30.0);
        const ConvexPolyhedron solid = makeConvexPolyhedron(boxHalfSpaces(box));
        // A coordinate c carries rounding of about 1e-16 |c| m, which moves the volume by a few 1e-16 |c| m^3 over the
        // box's faces (measured: 6e-17 |c| at 1e6 m, 3.2e-16 |c| at 9e7 m): 2e-15 |c| leaves a margin of 6.
        EXPECT_NEAR(solid.volume, 8.0, 2e-15 * std::max(1.0, maxAbsOf(centre))) << centre.x;
        ASSERT_EQ(solid.faces.size(), 6u);
        EXPECT_NEAR(glm::distance(0.5 * (solid.boundsMin + solid.boundsMax), centre), 0.0,
                    1e-12 * std::max(1.0, maxAbsOf(centre)));
    }
    // Beyond the world's limits it is refused, naming the limit.
    OrientedBox beyond;
    beyond.centre = Vec3(0.0, 0.0, 1e8);
    beyond.size = Vec3(1.0);
    const std::string message = inputErrorOf([&] { makeConvexPolyhedron(boxHalfSpaces(beyond)); });
    EXPECT_TRUE(contains(message, "world coordinates are limited to +-1e+08 m")) << message;
}

// A solid below the smallest size the format allows (1e-6 m, as polygons) is refused (the project reader names the
// limit for a box); one just above it is a solid, not "flat".
TEST(Polyhedron, TinySolidsAreRefusedAndSmallOnesKept) {
    OrientedBox box;
    box.size = Vec3(1e-7);
    EXPECT_FALSE(inputErrorOf([&] { makeConvexPolyhedron(boxHalfSpaces(box)); }).empty());
    box.size = Vec3(2e-6);
    EXPECT_NEAR(makeConvexPolyhedron(boxHalfSpaces(box)).volume, 8e-18, 1e-24);
}

TEST(Polyhedron, BoxHalfSpacesFaceOutwardsAndContainTheCentre) {
    OrientedBox box;
    box.centre = Vec3(1.0, 2.0, 3.0);
    box.size = Vec3(2.0, 4.0, 6.0);
    box.rotate = Vec3(0.0, 0.0, 90.0);
    const std::vector<HalfSpace> planes = boxHalfSpaces(box);
    ASSERT_EQ(planes.size(), 6u);
    for (const HalfSpace& plane : planes) {
        EXPECT_NEAR(glm::length(plane.normal), 1.0, 1e-12);
        EXPECT_LT(glm::dot(plane.normal, box.centre), plane.offset);
    }
    // Rotated 90 degrees about z, the box's 2 m x extent lies along y: y is within [1, 3].
    const ConvexPolyhedron solid = makeConvexPolyhedron(planes);
    EXPECT_NEAR(solid.boundsMin.y, 1.0, 1e-9);
    EXPECT_NEAR(solid.boundsMax.y, 3.0, 1e-9);
    EXPECT_NEAR(solid.boundsMin.x, -1.0, 1e-9);
    EXPECT_NEAR(solid.boundsMax.x, 3.0, 1e-9);
}

TEST(Polyhedron, TetrahedronFromFourPlanes) {
    const ConvexPolyhedron solid = makeConvexPolyhedron(unitTetrahedronPlanes());
    EXPECT_NEAR(solid.volume, 1.0 / 6.0, 1e-10);
    ASSERT_EQ(solid.faces.size(), 4u);
    for (const auto& face : solid.faces)
        EXPECT_EQ(face.size(), 3u);
    expectWellFormed(solid);
    EXPECT_NEAR(glm::distance(solid.boundsMin, Vec3(0.0)), 0.0, 1e-10);
    EXPECT_NEAR(glm::distance(solid.boundsMax, Vec3(1.0)), 0.0, 1e-10);
    // The planes are normalised.
    EXPECT_NEAR(glm::distance(solid.planes[3].normal, Vec3(1.0) / std::sqrt(3.0)), 0.0, 1e-15);
    EXPECT_NEAR(solid.planes[3].offset, 1.0 / std::sqrt(3.0), 1e-15);
}

TEST(Polyhedron, OctahedronWhosePlanesMeetAtItsVertices) {
    std::vector<HalfSpace> planes;
    for (double x : {-1.0, 1.0}) {
        for (double y : {-1.0, 1.0}) {
            for (double z : {-1.0, 1.0})
                planes.push_back({Vec3(x, y, z), 1.0});
        }
    }
    const ConvexPolyhedron solid = makeConvexPolyhedron(planes);
    EXPECT_NEAR(solid.volume, 4.0 / 3.0, 1e-10);
    ASSERT_EQ(solid.faces.size(), 8u);
    for (const auto& face : solid.faces)
        EXPECT_EQ(face.size(), 3u);
    expectWellFormed(solid);
}

TEST(Polyhedron, CubeWithItsCornersCutOff) {
    // |x|, |y|, |z| <= 1 and |x| + |y| + |z| <= 2: each corner loses a tetrahedron of volume 1/6.
    OrientedBox cube;
    cube.size = Vec3(2.0);
    std::vector<HalfSpace> planes = boxHalfSpaces(cube);
    for (double x : {-1.0, 1.0}) {
        for (double y : {-1.0, 1.0}) {
            for (double z : {-1.0, 1.0})
                planes.push_back({Vec3(x, y, z), 2.0});
        }
    }
    const ConvexPolyhedron solid = makeConvexPolyhedron(planes);
    EXPECT_NEAR(solid.volume, 8.0 - 8.0 / 6.0, 1e-9);
    EXPECT_EQ(solid.faces.size(), 14u);
    expectWellFormed(solid);
}

TEST(Polyhedron, RedundantPlanesAddNoFace) {
    std::vector<HalfSpace> planes = unitTetrahedronPlanes();
    planes.push_back({Vec3(1, 0, 0), 5.0});               // far away
    planes.push_back({Vec3(2, 2, 2), 2.0});               // the slanted plane again, scaled
    planes.push_back({Vec3(-1, -1, -1), 0.0});            // touches the vertex at the origin
    planes.push_back({Vec3(-1, -1, 0), 0.0});             // touches the edge along z
    planes.insert(planes.begin(), {Vec3(0, 0, 1), 3.0});  // redundant before the others cut anything
    const ConvexPolyhedron solid = makeConvexPolyhedron(planes);
    EXPECT_NEAR(solid.volume, 1.0 / 6.0, 1e-10);
    EXPECT_EQ(solid.faces.size(), 4u);
    EXPECT_EQ(solid.planes.size(), planes.size());
    expectWellFormed(solid);
}

TEST(Polyhedron, SmallSolidFarFromTheOrigin) {
    OrientedBox box;
    box.centre = Vec3(1000.0, -500.0, 20.0);
    box.size = Vec3(1e-3, 2e-3, 3e-3);
    box.rotate = Vec3(10.0, 20.0, 30.0);
    const ConvexPolyhedron solid = makeConvexPolyhedron(boxHalfSpaces(box));
    EXPECT_NEAR(solid.volume / 6e-9, 1.0, 1e-6);
    EXPECT_EQ(solid.faces.size(), 6u);
}

TEST(Polyhedron, ManyTangentPlanesMakeAClosedConvexSolid) {
    // Planes tangent to the unit sphere along a Fibonacci spiral: the solid circumscribes the sphere.
    std::vector<HalfSpace> planes;
    const int count = 200;
    const double golden = kPi * (3.0 - std::sqrt(5.0));
    for (int i = 0; i < count; ++i) {
        const double y = 1.0 - 2.0 * (i + 0.5) / count;
        const double r = std::sqrt(1.0 - y * y);
        planes.push_back({Vec3(r * std::cos(golden * i), y, r * std::sin(golden * i)), 1.0});
    }
    const ConvexPolyhedron solid = makeConvexPolyhedron(planes);
    EXPECT_GT(solid.volume, 4.0 / 3.0 * kPi);
    EXPECT_LT(solid.volume, 4.0 / 3.0 * kPi * 1.05);
    EXPECT_EQ(solid.faces.size(), planes.size());  // every plane touches the sphere, so every plane bounds the solid
    expectWellFormed(solid);

    // Euler's formula V - E + F = 2 holds when the faces share their vertices.
    std::vector<Vec3> vertices;
    std::size_t corners = 0;
    for (const auto& face : solid.faces) {
        corners += face.size();
        for (const Vec3& p : face) {
            const bool seen = std::any_of(vertices.begin(), vertices.end(),
                                          [&](const Vec3& q) { return glm::distance(p, q) < 1e-9; });
            if (!seen) vertices.push_back(p);
        }
    }
    const auto V = static_cast<long>(vertices.size()), E = static_cast<long>(corners / 2),
               F = static_cast<long>(solid.faces.size());
    EXPECT_EQ(V - E + F, 2);
}

TEST(Polyhedron, UnboundedHalfSpacesAreRefused) {
    const std::vector<std::vector<HalfSpace>> cases = {
        {{Vec3(-1, 0, 0), 0.0}, {Vec3(0, -1, 0), 0.0}, {Vec3(0, 0, -1), 0.0}},  // an octant
        {{Vec3(1, 0, 0), 1.0}, {Vec3(-1, 0, 0), 1.0}},                          // a slab
        {},                                                                     // all space
    };
    for (const auto& planes : cases) {
        const std::string message = inputErrorOf([&] { makeConvexPolyhedron(planes); });
        EXPECT_TRUE(contains(message, "do not bound a finite region")) << message;
    }
    OrientedBox box;
    std::vector<HalfSpace> fiveSides = boxHalfSpaces(box);
    fiveSides.pop_back();
    EXPECT_TRUE(contains(inputErrorOf([&] { makeConvexPolyhedron(fiveSides); }), "finite region"));
}

TEST(Polyhedron, EmptyIntersectionIsRefused) {
    std::vector<HalfSpace> planes = unitTetrahedronPlanes();
    planes.push_back({Vec3(-1, -1, -1), -2.0});  // x + y + z >= 2
    const std::string message = inputErrorOf([&] { makeConvexPolyhedron(planes); });
    EXPECT_TRUE(contains(message, "empty")) << message;
}

TEST(Polyhedron, FlatIntersectionIsRefused) {
    std::vector<HalfSpace> planes = unitTetrahedronPlanes();
    planes.push_back({Vec3(0, 0, 1), 0.0});  // z <= 0 leaves the bottom triangle only
    const std::string message = inputErrorOf([&] { makeConvexPolyhedron(planes); });
    EXPECT_TRUE(contains(message, "flat") || contains(message, "empty")) << message;

    OrientedBox box;
    std::vector<HalfSpace> thin = boxHalfSpaces(box);
    thin.push_back({Vec3(1, 0, 0), 1e-14});
    thin.push_back({Vec3(-1, 0, 0), 0.0});  // 0 <= x <= 1e-14
    const std::string thinMessage = inputErrorOf([&] { makeConvexPolyhedron(thin); });
    EXPECT_TRUE(contains(thinMessage, "flat") || contains(thinMessage, "empty")) << thinMessage;
}

TEST(Polyhedron, ZeroOrNonFiniteNormalsAreRefused) {
    std::vector<HalfSpace> planes = unitTetrahedronPlanes();
    planes[2].normal = Vec3(0.0);
    EXPECT_TRUE(contains(inputErrorOf([&] { makeConvexPolyhedron(planes); }), "plane 2 has a zero normal"));
    planes = unitTetrahedronPlanes();
    planes[1].normal.x = std::nan("");
    EXPECT_TRUE(contains(inputErrorOf([&] { makeConvexPolyhedron(planes); }), "plane 1"));
    planes = unitTetrahedronPlanes();
    planes[3].offset = INFINITY;
    EXPECT_TRUE(contains(inputErrorOf([&] { makeConvexPolyhedron(planes); }), "plane 3"));
}

// ---------------------------------------------------------------------------------------------------------------------
// Particle tetrahedra

TEST(Tetrahedron, VerticesAreAtScaleFromTheCentreAndEquidistant) {
    Particle particle;
    particle.centre = Vec3(1.0, 2.0, -3.0);
    particle.scale = 0.7;
    particle.orientation = glm::angleAxis(0.4, glm::normalize(Vec3(1.0, 2.0, 3.0)));
    const std::array<Vec3, 4> v = tetrahedronVertices(particle);
    Vec3 mean(0.0);
    for (const Vec3& p : v) {
        EXPECT_NEAR(glm::distance(p, particle.centre), particle.scale, 1e-12);
        mean += p / 4.0;
    }
    EXPECT_NEAR(glm::distance(mean, particle.centre), 0.0, 1e-12);
    const double edge = particle.scale * std::sqrt(8.0 / 3.0);
    for (int i = 0; i < 4; ++i) {
        for (int j = i + 1; j < 4; ++j)
            EXPECT_NEAR(glm::distance(v[i], v[j]), edge, 1e-12);
    }
}

TEST(Tetrahedron, OrientationRotatesTheVertices) {
    Particle particle;
    particle.scale = std::sqrt(3.0);
    const std::array<Vec3, 4> canonical = tetrahedronVertices(particle);
    EXPECT_NEAR(glm::distance(canonical[0], Vec3(1, 1, 1)), 0.0, 1e-12);
    EXPECT_NEAR(glm::distance(canonical[3], Vec3(-1, -1, 1)), 0.0, 1e-12);

    // 90 degrees about z takes (x, y, z) to (-y, x, z); the quaternion need not be unit length.
    particle.orientation = 3.0 * glm::angleAxis(kPi / 2.0, Vec3(0, 0, 1));
    const std::array<Vec3, 4> turned = tetrahedronVertices(particle);
    for (int i = 0; i < 4; ++i) {
        const Vec3 expected(-canonical[i].y, canonical[i].x, canonical[i].z);
        EXPECT_NEAR(glm::distance(turned[i], expected), 0.0, 1e-12);
    }
}

// ---------------------------------------------------------------------------------------------------------------------
// Polygons

const std::vector<Vec3> kSquare = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}};

TEST(Polygon, ValidSquareAndTriangle) {
    EXPECT_EQ(polygonProblem(kSquare), "");
    EXPECT_EQ(polygonProblem({{0, 2, 0}, {1, 2, 0}, {0, 2, 1}}), "");
    // A square in a tilted plane far from the origin, with a vertex in the middle of an edge.
    const Vec3 o(1e4, -2e3, 5e2), u = glm::normalize(Vec3(1, 1, 0)), v = glm::normalize(Vec3(-1, 1, 1));
    EXPECT_EQ(polygonProblem({o, o + u, o + 2.0 * u, o + 2.0 * u + v, o + v}), "");
}

TEST(Polygon, NormalFollowsTheRightHandRule) {
    EXPECT_NEAR(glm::distance(polygonNormal(kSquare), Vec3(0, 0, 1)), 0.0, 1e-15);
    const std::vector<Vec3> reversed(kSquare.rbegin(), kSquare.rend());
    EXPECT_NEAR(glm::distance(polygonNormal(reversed), Vec3(0, 0, -1)), 0.0, 1e-15);
    // Counter-clockwise seen from +x.
    EXPECT_NEAR(glm::distance(polygonNormal({{0, 0, 0}, {0, 1, 0}, {0, 0, 1}}), Vec3(1, 0, 0)), 0.0, 1e-15);
}

TEST(Polygon, AreaOfKnownPolygons) {
    EXPECT_NEAR(polygonArea(kSquare), 1.0, 1e-15);
    std::vector<Vec3> hexagon;  // regular, side 1, in a tilted plane
    const Vec3 u = glm::normalize(Vec3(1, 2, 3)), v = glm::normalize(glm::cross(u, Vec3(0, 0, 1)));
    for (int i = 0; i < 6; ++i) {
        hexagon.push_back(Vec3(5, 6, 7) + std::cos(kPi * i / 3.0) * u + std::sin(kPi * i / 3.0) * v);
    }
    EXPECT_EQ(polygonProblem(hexagon), "");
    EXPECT_NEAR(polygonArea(hexagon), 3.0 * std::sqrt(3.0) / 2.0, 1e-12);
    // The area is right for non-convex polygons too.
    EXPECT_NEAR(polygonArea({{0, 0, 0}, {2, 0, 0}, {2, 1, 0}, {1, 1, 0}, {1, 2, 0}, {0, 2, 0}}), 3.0, 1e-15);
}

TEST(Polygon, TooFewVerticesAreRefused) {
    EXPECT_TRUE(contains(polygonProblem({}), "at least 3"));
    EXPECT_TRUE(contains(polygonProblem({{0, 0, 0}, {1, 0, 0}}), "at least 3"));
}

TEST(Polygon, NonFiniteVerticesAreRefused) {
    std::vector<Vec3> polygon = kSquare;
    polygon[2].y = INFINITY;
    EXPECT_TRUE(contains(polygonProblem(polygon), "vertices[2]"));
}

TEST(Polygon, ClosedPolygonRepeatingTheFirstVertexIsRefused) {
    std::vector<Vec3> closed = kSquare;
    closed.push_back(kSquare[0]);
    EXPECT_TRUE(contains(polygonProblem(closed), "do not repeat the first vertex"));
}

TEST(Polygon, RepeatedConsecutiveVerticesAreRefused) {
    const std::string problem = polygonProblem({{0, 0, 0}, {1, 0, 0}, {1, 0, 0}, {1, 1, 0}});
    EXPECT_TRUE(contains(problem, "vertices[1] and vertices[2] are the same point")) << problem;
}

TEST(Polygon, CollinearVerticesHaveZeroArea) {
    const std::string problem = polygonProblem({{0, 0, 0}, {1, 1, 1}, {3, 3, 3}});
    EXPECT_TRUE(contains(problem, "zero area")) << problem;
}

TEST(Polygon, NonPlanarIsRefusedSayingByHowMuch) {
    const double h = 0.05;  // the vertices go up and down by h about the plane z = 0
    const std::string problem = polygonProblem({{0, 0, h}, {1, 0, -h}, {1, 1, h}, {0, 1, -h}});
    EXPECT_TRUE(contains(problem, "not planar")) << problem;
    EXPECT_TRUE(contains(problem, "is 0.05 m off")) << problem;

    std::vector<Vec3> almost = kSquare;
    almost[2].z = 1e-7;  // well within the tolerance
    EXPECT_EQ(polygonProblem(almost), "");
}

TEST(Polygon, NonConvexIsRefused) {
    const std::vector<Vec3> lShape = {{0, 0, 0}, {2, 0, 0}, {2, 1, 0}, {1, 1, 0}, {1, 2, 0}, {0, 2, 0}};
    const std::string l = polygonProblem(lShape);
    EXPECT_TRUE(contains(l, "not convex")) << l;
    EXPECT_TRUE(contains(l, "vertices[3]")) << l;

    const std::string bowtie = polygonProblem({{0, 0, 0}, {3, 0, 0}, {0, 1, 0}, {1, 1, 0}});
    EXPECT_TRUE(contains(bowtie, "not convex")) << bowtie;
    const std::string symmetricBowtie = polygonProblem({{0, 0, 0}, {1, 1, 0}, {1, 0, 0}, {0, 1, 0}});
    EXPECT_TRUE(contains(symmetricBowtie, "crosses itself")) << symmetricBowtie;

    std::vector<Vec3> pentagram;  // turns left at every vertex, but twice around
    for (int i = 0; i < 5; ++i)
        pentagram.push_back(Vec3(std::cos(4.0 * kPi * i / 5.0), std::sin(4.0 * kPi * i / 5.0), 0));
    const std::string star = polygonProblem(pentagram);
    EXPECT_TRUE(contains(star, "winds 2 times")) << star;

    const std::string foldBack = polygonProblem({{0, 0, 0}, {2, 0, 0}, {1, 0, 0}, {1, 1, 0}});
    EXPECT_TRUE(contains(foldBack, "folds back")) << foldBack;
}

}  // namespace
}  // namespace tyndall
