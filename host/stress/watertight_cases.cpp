// The stress suite's watertightness family (docs/stability.md).
#include <algorithm>
#include <cmath>
#include <map>
#include <set>

#include "stress/case_building.hpp"
#include "core/camera.hpp"
#include "core/random.hpp"

namespace dacrt {
namespace {

using namespace stress;

struct ClosedShape {
    std::string name;
    Mesh mesh;
    std::vector<Ball> inner;
};

std::vector<ClosedShape> closedShapes(StressSize size, Random& random) {
    const bool large = size == StressSize::Large;
    std::vector<ClosedShape> shapes;
    const int sphereDetail = large ? 4 : 2;

    // An icosphere's inscribed radius is above 0.79 of its radius at every subdivision.
    shapes.push_back({"icosphere", icosphere({0, 0, 0}, 1.0f, sphereDetail), {{{0, 0, 0}, 0.5}}});

    // Each vertex moved along its radius by up to 30%: faces stay farther than 0.6 from the
    // centre at these subdivisions (edges span under 0.3 rad).
    ClosedShape bumpy{"perturbed-sphere", icosphere({0, 0, 0}, 1.0f, sphereDetail), {{{0, 0, 0}, 0.3}}};
    for (glm::vec3& p : bumpy.mesh.positions) p *= float(1.0 + random.uniform(-0.3, 0.3));
    shapes.push_back(bumpy);

    // Tube radius 0.3 about a circle of radius 1; the balls sit on the circle at the ring
    // angles, where the cross-section is exactly the polygon.
    const int majorSegments = large ? 64 : 24, minorSegments = large ? 24 : 12;
    ClosedShape ring{"torus", torus({0, 0, 0}, 1.0f, 0.3f, majorSegments, minorSegments), {}};
    for (int i = 0; i < majorSegments; ++i) {
        const double u = 2.0 * M_PI * i / majorSegments;
        ring.inner.push_back({{std::cos(u), 0.0, std::sin(u)}, 0.15});
    }
    shapes.push_back(ring);

    shapes.push_back({"cube", box({-1, -1, -1}, {1, 1, 1}), {{{0, 0, 0}, 0.5}}});
    ClosedShape slab{"flat-box", box({-1.0f, -0.25f, -0.5f}, {1.0f, 0.25f, 0.5f}), {}};
    for (double x : {-0.75, -0.25, 0.25, 0.75}) slab.inner.push_back({{x, 0.0, 0.0}, 0.125});
    shapes.push_back(slab);

    // Radius 0.02, length 2 along y: a needle-like closed mesh of long thin triangles.
    const int segments = large ? 32 : 12, rings = large ? 32 : 8;
    ClosedShape needle{"thin-cylinder", cylinder({0.0f, -1.0f, 0.0f}, 0.02f, 2.0f, segments, rings), {}};
    for (int r = 1; r < rings; ++r) needle.inner.push_back({{0.0, -1.0 + 2.0 * r / rings, 0.0}, 0.009});
    shapes.push_back(needle);
    return shapes;
}

ClosedShape placed(const ClosedShape& unit, double scale, const glm::dvec3& offset) {
    ClosedShape s = unit;
    for (glm::vec3& p : s.mesh.positions) p = glm::vec3(glm::dvec3(p) * scale + offset);
    for (Ball& b : s.inner) b = {b.centre * scale + offset, b.radius * scale};
    return s;
}

// A shape is only meaningful where float32 resolves it: its smallest inner ball must span
// thousands of units in the last place at the offset.
bool representable(const ClosedShape& unit, double scale, const glm::dvec3& offset) {
    double smallest = 1e300;
    for (const Ball& b : unit.inner) smallest = std::min(smallest, b.radius * scale);
    const double magnitude = std::max({std::abs(offset.x), std::abs(offset.y), std::abs(offset.z)}) + 2.0 * scale;
    const double ulp = std::ldexp(1.0, std::ilogb(magnitude) - 23);
    return smallest >= 4096.0 * ulp;
}

void addShapeCases(std::vector<StressCase>& out, const ClosedShape& s, const std::string& label, StressSize size,
                   Random& random) {
    const bool large = size == StressSize::Large;
    const std::vector<std::pair<std::uint32_t, std::uint32_t>> edges = edgesOf(s.mesh);
    const std::vector<Triangle> triangles = trianglesOf({s.mesh});
    Box bounds;
    for (const glm::vec3& p : s.mesh.positions) bounds.extend(p);
    const glm::dvec3 centre = (glm::dvec3(bounds.lo) + glm::dvec3(bounds.hi)) * 0.5;
    const double radius = 0.5 * glm::length(glm::dvec3(bounds.hi) - glm::dvec3(bounds.lo));
    auto aimAtSurface = [&](RayFan& fan) {
        for (const glm::vec3& p : s.mesh.positions) fan.towards(glm::dvec3(p));
        for (const auto& [a, b] : edges)
            fan.towards(0.5 * (glm::dvec3(s.mesh.positions[a]) + glm::dvec3(s.mesh.positions[b])));
    };

    // From inside: every ray must hit.
    const int insideOrigins = std::min<int>(int(s.inner.size()), 2);
    for (int k = 0; k < insideOrigins; ++k) {
        const Ball& b = s.inner[std::size_t(k * (int(s.inner.size()) - 1) / std::max(1, insideOrigins - 1))];
        StressCase c{"watertight", label + " inside#" + std::to_string(k), triangles, {}, {}, {}};
        const glm::vec3 origin = glm::vec3(b.centre + (k == 0 ? glm::dvec3(0.0) : random.onSphere() * 0.5 * b.radius));
        RayFan fan(c, origin, true);
        aimAtSurface(fan);
        for (int i = 0, n = large ? 12000 : 5600; i < n; ++i) fan.along(random.onSphere());
        out.push_back(std::move(c));
    }

    // From outside, on the axes (so that rays to the centre are axis-parallel) and at random:
    // rays through vertices, edges and the inner balls.
    const std::vector<glm::dvec3> sides = {{0, 0, 1}, {-1, 0, 0}, {0, -1, 0}, random.onSphere()};
    for (std::size_t k = 0; k < sides.size(); ++k) {
        StressCase c{"watertight", label + " outside#" + std::to_string(k), triangles, {}, {}, {}};
        RayFan fan(c, glm::vec3(centre + sides[k] * (3.0 * radius)), false, &s.inner);
        aimAtSurface(fan);
        for (const Ball& b : s.inner) {
            fan.towards(b.centre);
            for (int i = 0, n = large ? 80 : 24; i < n; ++i)
                fan.towards(b.centre + random.onSphere() * (0.7 * b.radius * random.uniform()));
        }
        out.push_back(std::move(c));
    }
}

}  // namespace

std::vector<StressCase> watertightCases(StressSize size, std::uint64_t seed) {
    Random random(seed);
    const std::vector<ClosedShape> shapes = closedShapes(size, random);
    const std::vector<double> scales = {1e-4, 1e-2, 1.0, 1e2, 1e4, 1e6};
    const glm::dvec3 direction(1.0, -0.7, 0.4);  // offsets on no axis, largest component 1
    const std::vector<double> offsets = {0.0, 1e2, 1e4, 1e6};
    std::vector<StressCase> out;
    for (const ClosedShape& unit : shapes)
        for (double scale : scales)
            for (double offset : offsets) {
                if (!representable(unit, scale, direction * offset)) continue;
                const std::string label = unit.name + " scale " + number(scale) + " offset " + number(offset);
                addShapeCases(out, placed(unit, scale, direction * offset), label, size, random);
            }
    return out;
}

}  // namespace dacrt
