// Reference integrals over spherical polygons for the LTSD tests: adaptive quadrature in double, independent of the
// shared edge-integral code, and random polygons of the kinds the LTSD issue lists (tiny to ~2 sr, straddling the
// horizon, around a pole).
#ifndef TYNDALL_TEST_POLYGON_QUADRATURE_H
#define TYNDALL_TEST_POLYGON_QUADRATURE_H

#include "shared/ltsd.h"
#include "stats.h"
#include "tyndall/tables/ltsd_table.h"

#include <glm/glm.hpp>

#include <algorithm>
#include <cmath>
#include <random>
#include <string>
#include <vector>

namespace tyndall::test {

// Adaptive quadrature over a polygon (the library's reference integral; the fan about `centre` is signed).
template <typename F>
double integrateOverPolygon(const glm::dvec3& centre, const std::vector<glm::dvec3>& vertices, const F& f,
                            double tolerance = 1e-11, double relativeTolerance = 1e-9) {
    return integrateOverSphericalPolygon(vertices, centre, f, tolerance, relativeTolerance);
}

// The part of a polygon with side * z >= 0, in double (an independent check of the shared float clipping), so that the
// reference integrals never straddle the horizon's kink or jump. Empty when nothing is left.
inline std::vector<glm::dvec3> clipToHemisphere(const std::vector<glm::dvec3>& v, double side) {
    std::vector<glm::dvec3> out;
    for (size_t i = 0; i < v.size(); ++i) {
        const glm::dvec3 a = glm::normalize(v[i]), b = glm::normalize(v[(i + 1) % v.size()]);
        const double da = side * a.z, db = side * b.z;
        if (da >= 0.0) out.push_back(a);
        if ((da > 0.0 && db < 0.0) || (da < 0.0 && db > 0.0)) {
            glm::dvec3 c = a + (b - a) * (da / (da - db));
            c.z = 0.0;
            out.push_back(glm::normalize(c));
        }
    }
    if (out.size() < 3) out.clear();
    return out;
}

// The integral of f over the part of the polygon with side * z >= 0.
template <typename F>
double integrateOverHalf(const std::vector<glm::dvec3>& vertices, double side, const F& f, double tolerance,
                         double relativeTolerance) {
    const std::vector<glm::dvec3> half = clipToHemisphere(vertices, side);
    if (half.empty()) return 0.0;
    glm::dvec3 centre(0.0);
    for (const glm::dvec3& v : half) centre += v;
    return integrateOverSphericalPolygon(half, centre, f, tolerance, relativeTolerance);
}

struct TestPolygon {
    glm::dvec3 centre;
    std::vector<glm::dvec3> vertices;
    const char* kind;
};

inline glm::dvec3 unitFromAngles(double cosTheta, double phi) {
    const double s = std::sqrt(std::max(0.0, 1.0 - cosTheta * cosTheta));
    return {s * std::cos(phi), s * std::sin(phi), cosTheta};
}

// A polygon of `count` vertices at angular radius about radius * [0.75, 1] around `centre`, at sorted random azimuths
// with gaps below pi: star-shaped about the centre.
inline TestPolygon polygonAround(const glm::dvec3& centre, double radius, int count, std::mt19937& rng,
                                 const char* kind) {
    std::uniform_real_distribution<double> u(0.0, 1.0);
    glm::dvec3 t = std::abs(centre.z) < 0.9 ? glm::dvec3(0, 0, 1) : glm::dvec3(1, 0, 0);
    t = glm::normalize(glm::cross(t, centre));
    const glm::dvec3 b = glm::cross(centre, t);
    std::vector<double> phis;
    for (int i = 0; i < count; ++i) phis.push_back(2.0 * 3.14159265358979 * (i + 0.3 * u(rng)) / count);
    TestPolygon p{centre, {}, kind};
    for (double phi : phis) {
        const double r = radius * (0.75 + 0.25 * u(rng));
        p.vertices.push_back(std::cos(r) * centre + std::sin(r) * (std::cos(phi) * t + std::sin(phi) * b));
    }
    return p;
}

// The kinds of polygons the tests cover, several of each: tiny (1e-4 .. 1e-3 sr), medium, large (~2 sr), straddling
// the horizon, around +z and around -z (the peak of HG for g < 0 and g > 0 respectively), near the horizon.
inline std::vector<TestPolygon> randomTestPolygons(unsigned seed, int perKind) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> u(0.0, 1.0);
    std::vector<TestPolygon> polygons;
    const auto anyDirection = [&] { return unitFromAngles(2.0 * u(rng) - 1.0, 6.283185307179586 * u(rng)); };
    for (int i = 0; i < perKind; ++i) {
        const int count = 3 + int(u(rng) * 6.0);  // 3 .. 8 vertices
        polygons.push_back(polygonAround(anyDirection(), 0.006 + 0.012 * u(rng), count, rng, "tiny"));
        polygons.push_back(polygonAround(anyDirection(), 0.1 + 0.3 * u(rng), count, rng, "medium"));
        polygons.push_back(polygonAround(anyDirection(), 0.75 + 0.05 * u(rng), count, rng, "large"));
        polygons.push_back(polygonAround(unitFromAngles(0.2 * u(rng) - 0.1, 6.283185307179586 * u(rng)),
                                         0.2 + 0.5 * u(rng), count, rng, "horizon"));
        polygons.push_back(polygonAround(unitFromAngles(0.98 + 0.02 * u(rng), 6.283185307179586 * u(rng)),
                                         0.1 + 0.6 * u(rng), count, rng, "pole+z"));
        polygons.push_back(polygonAround(unitFromAngles(-0.98 - 0.02 * u(rng), 6.283185307179586 * u(rng)),
                                         0.1 + 0.6 * u(rng), count, rng, "pole-z"));
    }
    return polygons;
}

inline shader::SphericalPolygon toShaderPolygon(const TestPolygon& p) {
    shader::SphericalPolygon s{};
    s.count = int(p.vertices.size());
    for (size_t i = 0; i < p.vertices.size(); ++i)
        s.v[i] = glm::vec3(p.vertices[i]);
    return s;
}

// The polygons of S's accuracy targets (issue 32): solid angles log-uniform over [0.01, 2] sr, centred anywhere, on
// either pole, across the horizon, or beside a pole so that an edge passes within a fraction of the polygon's radius of
// it (the peak of HG at -z for g > 0, +z for g < 0). Each polygon's solid angle is measured and kept within the range.
inline std::vector<TestPolygon> sAccuracyPolygons(unsigned seed, int perKind) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> u(0.0, 1.0);
    const double twoPi = 6.283185307179586;
    const char* kinds[] = {"random", "pole+z", "pole-z", "horizon", "beside+z", "beside-z"};
    std::vector<TestPolygon> polygons;
    for (const char* kind : kinds) {
        const std::string k = kind;
        for (int made = 0; made < perKind;) {
            const double omega = 0.01 * std::exp(std::log(200.0) * u(rng));
            const double radius = 1.25 * std::acos(1.0 - omega / twoPi);
            const int count = 3 + int(u(rng) * 6.0);
            const double sign = k.find('-') != std::string::npos ? -1.0 : 1.0;  // the pole of pole-z, beside-z
            glm::dvec3 centre;
            if (k == "random")
                centre = unitFromAngles(2.0 * u(rng) - 1.0, twoPi * u(rng));
            else if (k == "horizon")
                centre = unitFromAngles(0.1 * (2.0 * u(rng) - 1.0), twoPi * u(rng));
            else if (k.rfind("pole", 0) == 0)
                centre = unitFromAngles(sign * std::cos(0.5 * radius * u(rng)), twoPi * u(rng));
            else
                centre = unitFromAngles(sign * std::cos(std::min(1.5, radius * (0.8 + 0.4 * u(rng)))), twoPi * u(rng));
            TestPolygon p = polygonAround(centre, radius, count, rng, kind);
            const double measured = double(shader::ltsdSolidAngle(toShaderPolygon(p)));
            if (measured < 0.01 || measured > 2.0) continue;
            polygons.push_back(p);
            ++made;
        }
    }
    return polygons;
}

}  // namespace tyndall::test

#endif  // TYNDALL_TEST_POLYGON_QUADRATURE_H
