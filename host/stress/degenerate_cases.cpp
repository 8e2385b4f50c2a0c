// The stress suite's degenerate-geometry family (docs/stability.md).
#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <set>

#include "stress/case_building.hpp"
#include "core/camera.hpp"
#include "core/random.hpp"

namespace dacrt {
namespace {

using namespace stress;

glm::vec3 onPlanesSometimes(glm::dvec3 p, Random& random) {
    // A third of the points get a coordinate exactly on a first-level split plane.
    if (random.uniform() < 1.0 / 3.0) p[int(random.uniform() * 3.0) % 3] = 0.0;
    return glm::vec3(p);
}

std::vector<StressCase> degenerateCasesImpl(StressSize size, Random& random) {
    const bool large = size == StressSize::Large;
    std::vector<StressCase> out;
    const int count = large ? 2000 : 300;
    const int randomRays = large ? 4000 : 600;

    auto finish = [&](StressCase& c, const std::vector<glm::vec3>& origins, const std::vector<glm::dvec3>& targets,
                      bool inside) {
        for (std::size_t k = 0; k < origins.size(); ++k) {
            StressCase shot = c;
            shot.name += " from " + std::to_string(k);
            RayFan fan(shot, origins[k], inside);
            for (const glm::dvec3& t : targets) fan.towards(t);
            for (int i = 0; i < randomRays; ++i) fan.along(random.onSphere());
            out.push_back(std::move(shot));
        }
    };
    auto targetsOf = [](const std::vector<Triangle>& tris, std::size_t first) {
        std::vector<glm::dvec3> t;
        for (std::size_t i = first; i < tris.size(); ++i) {
            const glm::dvec3 a(tris[i].v0), b(tris[i].v1), c(tris[i].v2);
            for (const glm::dvec3& p : {a, b, c, (a + b) * 0.5, (b + c) * 0.5, (c + a) * 0.5, (a + b + c) / 3.0})
                t.push_back(p);
        }
        return t;
    };
    const std::vector<Triangle> roomTriangles = trianglesOf({room()});
    const std::vector<glm::vec3> insideOrigins = {{0.1f, 0.2f, -0.3f}, {0, 0, 0}};

    {
        // Zero area: a point, two equal vertices, and three exactly collinear vertices.
        StressCase c{"degenerate", "zero-area", roomTriangles, {}, {}, {}};
        for (int i = 0; i < count; ++i) {
            const glm::vec3 a = onPlanesSometimes(random.inBox(-0.9, 0.9), random);
            const glm::vec3 step = glm::vec3(glm::ldexp(glm::dvec3(random.inBox(-1.0, 1.0)), glm::ivec3(-3)));
            switch (i % 3) {
                case 0: c.triangles.push_back({a, 0, a, 0, a, 0}); break;
                case 1: c.triangles.push_back({a, 0, a, 0, a + step, 0}); break;
                default: {
                    // Exactly collinear: a, a + s, a + 2s with s along one axis, so that
                    // rounding moves the points along their line, never off it.
                    glm::vec3 s(0.0f);
                    s[(i / 3) % 3] = 0.125f;
                    c.triangles.push_back({a, 0, a + s, 0, a + 2.0f * s, 0});
                }
            }
        }
        finish(c, insideOrigins, targetsOf(c.triangles, roomTriangles.size()), true);
    }
    {
        // Needles (one edge of 1e-6) and slivers (a vertex 1e-6 from the opposite edge).
        StressCase c{"degenerate", "needles and slivers", roomTriangles, {}, {}, {}};
        for (int i = 0; i < count; ++i) {
            const glm::dvec3 a = random.inBox(-0.9, 0.9);
            const glm::dvec3 b = a + random.onSphere() * random.uniform(0.1, 0.8);
            const glm::dvec3 tiny = random.onSphere() * 1e-6;
            const glm::dvec3 c3 = i % 2 == 0 ? a + tiny : (a + b) * 0.5 + tiny;
            c.triangles.push_back({glm::vec3(a), 0, glm::vec3(b), 0, glm::vec3(c3), 0});
        }
        finish(c, insideOrigins, targetsOf(c.triangles, roomTriangles.size()), true);
    }
    {
        // Repeated vertices: a sphere whose triangles each carry their own copies of the
        // shared positions, and the same sphere again with each triangle's vertices rotated.
        StressCase c{"degenerate", "repeated vertices", roomTriangles, {}, {}, {}};
        const std::vector<Triangle> sphere = trianglesOf({icosphere({0.2f, -0.1f, 0.0f}, 0.5f, large ? 4 : 2)});
        for (const Triangle& t : sphere) c.triangles.push_back(t);
        for (const Triangle& t : sphere) c.triangles.push_back({t.v1, 0, t.v2, 0, t.v0, 0});
        finish(c, {{0.2f, -0.1f, 0.0f}, {0.9f, 0.9f, 0.9f}}, targetsOf(sphere, 0), true);
    }
    {
        // A size ratio of 10^6: a room of half-size 1000 and triangles of size 1e-3 about
        // the origin.
        StressCase c{"degenerate", "size ratio 1e6", trianglesOf({box({-1000, -1000, -1000}, {1000, 1000, 1000})}), {}, {}, {}};
        const std::size_t first = c.triangles.size();
        for (int i = 0; i < count * 2; ++i) {
            const glm::dvec3 p = random.inBox(-1.0, 1.0);
            const glm::dvec3 u = random.onSphere() * 1e-3, v = random.onSphere() * 1e-3;
            c.triangles.push_back({glm::vec3(p), 0, glm::vec3(p + u), 0, glm::vec3(p + v), 0});
        }
        for (int i = 0; i < 8; ++i) {  // and a few of size 1e3 through the middle
            const glm::dvec3 p = random.inBox(-500.0, 500.0);
            c.triangles.push_back({glm::vec3(p), 0, glm::vec3(p + random.onSphere() * 1e3), 0,
                                   glm::vec3(p + random.onSphere() * 1e3), 0});
        }
        finish(c, {{0.05f, 0.01f, 0.02f}, {3.0f, -2.0f, 1.0f}}, targetsOf(c.triangles, first), true);
    }
    {
        // Coincident triangles: groups of identical copies (the tie rule decides) across the
        // split planes, plus a group with rotated vertex order (same plane, own rounding).
        StressCase c{"degenerate", "coincident", roomTriangles, {}, {}, {}};
        const std::size_t first = c.triangles.size();
        for (int g = 0; g < 6; ++g) {
            const Triangle t{glm::vec3(random.inBox(-0.9, -0.1)), 0, glm::vec3(random.inBox(0.1, 0.9)), 0,
                             onPlanesSometimes(random.inBox(-0.9, 0.9), random), 0};
            std::vector<std::uint32_t> group;
            for (int k = 0, copies = large ? 64 : 16; k < copies; ++k) {
                group.push_back(std::uint32_t(c.triangles.size()));
                c.triangles.push_back(t);
                c.triangles.push_back({t.v1, 0, t.v2, 0, t.v0, 0});  // interleaved rotated copies
            }
            c.coincidentGroups.push_back(group);
        }
        finish(c, insideOrigins, targetsOf(c.triangles, first), true);
    }
    {
        // Every triangle straddles the first split on every axis: one vertex near each of
        // two opposite corners. No room, so rays may miss; they are compared, not leak-counted.
        StressCase c{"degenerate", "all straddle", {}, {}, {}, {}};
        for (int i = 0; i < count; ++i) {
            const glm::dvec3 lo = random.inBox(-1.0, -0.5), hi = random.inBox(0.5, 1.0);
            c.triangles.push_back({glm::vec3(lo), 0, glm::vec3(hi), 0, glm::vec3(random.inBox(-1.0, 1.0)), 0});
        }
        finish(c, {{0, 0, 0}, {0.0f, 0.0f, 4.0f}, {-3.0f, 2.0f, 1.0f}}, targetsOf(c.triangles, 0), false);
    }
    return out;
}

// Whether float32 resolves a room of half-size `scale` at `offset`: thousands of units in
// the last place across it.
bool resolvable(double scale, const glm::dvec3& offset) {
    const double magnitude = std::max({std::abs(offset.x), std::abs(offset.y), std::abs(offset.z)}) + 2.0 * scale;
    return scale >= 4096.0 * std::ldexp(1.0, std::ilogb(magnitude) - 23);
}

// One step of float32 towards +infinity on one coordinate: a zero-area triangle becomes a
// sliver whose area is representable.
glm::vec3 nudged(glm::vec3 p, int axis) {
    p[axis] = std::nextafter(p[axis], std::numeric_limits<float>::infinity());
    return p;
}

// Degenerate and nearly degenerate triangles, and rays that meet their supporting lines far
// beyond their ends: the shape of the defect found on a scanned mesh (docs/stability.md). For
// such a ray the exact edge values are tiny multiples of one another, so their rounding
// decides the sign test; without the predicate's rules the "hit" lands far from the triangle,
// where no DACRT cell brings the two together. Segments along the rays' directions and across
// them, points, pairs of equal vertices, and slivers one unit in the last place wide, in a
// closed room, at every scale and offset of the watertightness family. Rays from inside the
// room must hit it; rays from outside are compared with brute force only.
void addEndOnCases(std::vector<StressCase>& out, StressSize size, Random& random) {
    const bool large = size == StressSize::Large;
    const int count = large ? 1200 : 120;
    const glm::dvec3 direction(1.0, -0.7, 0.4);
    for (double scale : {1e-4, 1e-2, 1.0, 1e2, 1e4, 1e6})
        for (double offset : {0.0, 1e2, 1e4, 1e6}) {
            const glm::dvec3 shift = direction * offset;
            if (!resolvable(scale, shift)) continue;
            auto at = [&](const glm::dvec3& unit) { return glm::vec3(unit * scale + shift); };
            // Inside the room, and far outside it (as the scan's default front view was).
            const std::vector<std::pair<glm::dvec3, bool>> eyes = {{{0.1, 0.2, -0.3}, true}, {{0.05, 0.27, 30.0}, false}};
            for (std::size_t k = 0; k < eyes.size(); ++k) {
                const auto& [eye, inside] = eyes[k];
                StressCase c{"degenerate", "end-on scale " + number(scale) + " offset " + number(offset) + " from " +
                                               std::to_string(k),
                             {}, {}, {}, {}};
                Mesh walls = room();
                for (glm::vec3& p : walls.positions) p = at(glm::dvec3(p));
                c.triangles = trianglesOf({walls});
                const glm::vec3 origin = at(eye);
                RayFan fan(c, origin, inside);
                for (int i = 0; i < count; ++i) {
                    const glm::dvec3 p = random.inBox(-0.9, 0.9);
                    // Along: nearly the direction from the eye; across: any direction.
                    glm::dvec3 v = i % 2 == 0 ? glm::normalize(p - eye) + random.onSphere() * 1e-3 : random.onSphere();
                    v *= random.uniform(0.02, 0.2);
                    Triangle t{};
                    switch (i % 8) {
                        case 0:
                        case 1: t = {at(p), 0, at(p + v), 0, at(p + 0.4 * v), 0}; break;              // collinear
                        case 2: t = {at(p), 0, at(p), 0, at(p), 0}; break;                             // a point
                        case 3: t = {at(p), 0, at(p), 0, at(p + v), 0}; break;                         // two equal
                        default: t = {at(p), 0, nudged(at(p + v), i % 3), 0, at(p + 0.4 * v), 0};     // sliver
                    }
                    c.triangles.push_back(t);
                    // Rays through the supporting line beyond both ends, and one through the middle.
                    for (double lambda : {-1.5, -0.3, 0.5, 1.4, 3.0}) fan.towards(p * scale + shift + lambda * scale * v);
                }
                // Segments along a coordinate axis (all three vertices share the other two
                // coordinates exactly, as a scan's vertical "stalactites" do), and slivers one unit
                // in the last place off them, under a whole pinhole image: where the scanned mesh
                // failed.
                for (int i = 0; i < count * 8; ++i) {
                    const glm::dvec3 p = random.inBox(-0.9, 0.9);
                    const int axis = i % 4 == 3 ? i % 3 : 2;  // mostly along the view axis
                    glm::dvec3 step(0.0);
                    step[axis] = random.uniform(-0.02, 0.02);
                    const glm::dvec3 step2 = step * random.uniform(-1.0, 1.0);
                    glm::vec3 middle = at(p + step2);
                    if (i % 2 == 1) middle = nudged(middle, (axis + 1) % 3);
                    c.triangles.push_back({at(p), 0, middle, 0, at(p + step), 0});
                }
                addPinhole(fan, glm::normalize(-eye), {0, 1, 0}, large ? 161 : 49, large ? 121 : 37, inside ? 70.0 : 4.0);
                out.push_back(std::move(c));
            }
        }
}

}  // namespace

std::vector<StressCase> degenerateCases(StressSize size, std::uint64_t seed) {
    Random random(seed + 2);
    std::vector<StressCase> out = degenerateCasesImpl(size, random);
    addEndOnCases(out, size, random);
    return out;
}

}  // namespace dacrt
