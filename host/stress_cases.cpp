#include "stress_cases.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <random>
#include <set>

#include "camera.hpp"
#include "errors.hpp"
#include "procedural.hpp"

namespace dacrt {
namespace {

// A ball that lies inside a closed mesh: a ray that starts outside the mesh and reaches the
// ball at t > 0 must cross the surface on the way.
struct Ball {
    glm::dvec3 centre;
    double radius;
};

struct ClosedShape {
    std::string name;
    Mesh mesh;
    std::vector<Ball> inner;
};

// Portable uniform numbers (the standard distributions differ between libraries).
class Random {
public:
    explicit Random(std::uint64_t seed) : engine_(seed) {}
    double uniform() { return double(engine_() >> 11) * 0x1p-53; }
    double uniform(double lo, double hi) { return lo + (hi - lo) * uniform(); }
    glm::dvec3 inBox(double lo, double hi) { return {uniform(lo, hi), uniform(lo, hi), uniform(lo, hi)}; }
    glm::dvec3 onSphere() {
        for (;;) {
            const glm::dvec3 p = inBox(-1.0, 1.0);
            const double l = glm::length(p);
            if (l > 1e-3 && l <= 1.0) return p / l;
        }
    }

private:
    std::mt19937_64 engine_;
};

std::string number(double x) {
    char text[32];
    std::snprintf(text, sizeof text, "%g", x);
    return text;
}

std::vector<Triangle> trianglesOf(const std::vector<Mesh>& meshes) {
    std::vector<Triangle> out;
    for (const Mesh& m : meshes)
        for (std::size_t i = 0; i + 2 < m.indices.size(); i += 3)
            out.push_back(Triangle{m.positions[m.indices[i]], 0.0f, m.positions[m.indices[i + 1]], 0.0f,
                                   m.positions[m.indices[i + 2]], 0.0f});
    return out;
}

std::vector<std::pair<std::uint32_t, std::uint32_t>> edgesOf(const Mesh& m) {
    std::set<std::pair<std::uint32_t, std::uint32_t>> edges;
    for (std::size_t i = 0; i + 2 < m.indices.size(); i += 3)
        for (int e = 0; e < 3; ++e) edges.insert(std::minmax(m.indices[i + e], m.indices[i + (e + 1) % 3]));
    return {edges.begin(), edges.end()};
}

// Builds the case's rays from one origin towards targets (points) and along directions.
// mustHit marks every ray when the origin lies inside a closed surface; otherwise only
// rays whose line passes well inside one of the balls at t > 0.
class RayFan {
public:
    RayFan(StressCase& c, const glm::vec3& origin, bool originInside, const std::vector<Ball>* balls = nullptr)
        : case_(c), origin_(origin), inside_(originInside), balls_(balls) {}

    void towards(const glm::dvec3& target) {
        const glm::dvec3 d = target - glm::dvec3(origin_);
        if (glm::length(d) == 0.0) return;  // a target at the origin gives no direction
        along(d);
    }
    void along(const glm::dvec3& direction) {
        const Ray r = makeRay(origin_, direction);
        case_.rays.push_back(r);
        case_.mustHit.push_back(inside_ || certainlyEntersBall(r) ? 1 : 0);
    }

private:
    bool certainlyEntersBall(const Ray& r) const {
        if (!balls_) return false;
        const glm::dvec3 o(r.origin), d(r.dir);
        for (const Ball& b : *balls_) {
            const double t = glm::dot(b.centre - o, d) / glm::dot(d, d);
            if (t <= 0.0) continue;
            if (glm::length(o + t * d - b.centre) < 0.8 * b.radius) return true;
        }
        return false;
    }

    StressCase& case_;
    glm::vec3 origin_;
    bool inside_;
    const std::vector<Ball>* balls_;
};

// ---- watertightness -------------------------------------------------------------------

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

// ---- split planes -----------------------------------------------------------------------

// The room [-1, 1]^3: every ray from inside it must hit something.
Mesh room() { return box({-1, -1, -1}, {1, 1, 1}); }

// Grids in the planes the spatial-median splits and the region slabs of the room use
// (x = 0, y = 0, z = 0, then +-0.5, +-0.25, ...), with vertices on dyadic coordinates so
// that they fall exactly on cell boundaries. Each covers part of its plane only.
std::vector<Mesh> splitPlaneGrids() {
    return {grid({0.0f, -1.0f, -0.5f}, {0, 1.5f, 0}, {0, 0, 1.5f}, 6, 6),
            grid({-1.0f, 0.0f, -1.0f}, {1.5f, 0, 0}, {0, 0, 1.0f}, 12, 8),
            grid({-0.5f, -0.5f, 0.0f}, {1.5f, 0, 0}, {0, 1.5f, 0}, 6, 12),
            grid({0.5f, -1.0f, -1.0f}, {0, 2.0f, 0}, {0, 0, 0.75f}, 8, 3),
            grid({-1.0f, -0.5f, -1.0f}, {0.75f, 0, 0}, {0, 0, 2.0f}, 3, 8),
            grid({-1.0f, -1.0f, 0.25f}, {1.0f, 0, 0}, {0, 1.0f, 0}, 4, 4),
            grid({0.0f, 0.0f, -0.75f}, {1.0f, 0, 0}, {0, 1.0f, 0}, 8, 8)};
}

std::vector<Mesh> roomWithShapes() {
    std::vector<Mesh> m = {room(), icosphere({0.5f, 0.5f, -0.5f}, 0.3f, 2),
                           torus({-0.5f, -0.25f, 0.5f}, 0.3f, 0.1f, 24, 12),
                           box({0.25f, -0.75f, 0.25f}, {0.75f, -0.25f, 0.75f}),
                           cylinder({-0.5f, -1.0f, -0.5f}, 0.05f, 2.0f, 12, 8)};
    for (Mesh& g : splitPlaneGrids()) m.push_back(g);
    return m;
}

// Pinhole rays of an odd-sized image, so that the centre row and column have exactly zero
// components: they travel inside the planes through the camera.
void addPinhole(RayFan& fan, const glm::dvec3& forward, const glm::dvec3& up, int width, int height) {
    const glm::dvec3 right = glm::normalize(glm::cross(forward, up));
    const double tanHalf = std::tan(0.5 * glm::radians(70.0));
    for (int y = 0; y < height; ++y)
        for (int x = 0; x < width; ++x) {
            const double sx = (2.0 * (x + 0.5) / width - 1.0) * tanHalf * double(width) / height;
            const double sy = (1.0 - 2.0 * (y + 0.5) / height) * tanHalf;
            fan.along(forward + sx * right + sy * up);
        }
}

std::vector<StressCase> splitPlaneCasesImpl(StressSize size, Random& random) {
    const bool large = size == StressSize::Large;
    std::vector<StressCase> out;
    const int width = large ? 129 : 41, height = large ? 97 : 31;

    {
        // Triangles in split planes, seen from points on those planes: the rays to the
        // grids' vertices travel inside the grids' planes.
        std::vector<Mesh> meshes = splitPlaneGrids();
        meshes.insert(meshes.begin(), room());
        const std::vector<Triangle> triangles = trianglesOf(meshes);
        const std::vector<glm::vec3> origins = {{0, 0, 0},       {0, 0.5f, -0.25f}, {0.5f, 0, 0.75f},
                                                {-0.25f, 0.25f, 0}, {0.3f, 0.2f, 0.1f}};
        for (std::size_t k = 0; k < origins.size(); ++k) {
            StressCase c{"split-plane", "planes from " + std::to_string(k), triangles, {}, {}, {}};
            RayFan fan(c, origins[k], true);
            for (const Mesh& m : meshes)
                for (const glm::vec3& p : m.positions) fan.towards(glm::dvec3(p));
            for (int i = 0, n = large ? 4000 : 500; i < n; ++i) fan.along(random.onSphere());
            out.push_back(std::move(c));
        }
    }
    {
        // The camera exactly on split planes and region boundaries, inside the scene,
        // looking along each axis: rays in the planes through it, one axis-parallel ray.
        const std::vector<Triangle> triangles = trianglesOf(roomWithShapes());
        const std::vector<glm::vec3> eyes = {{0, 0, 0}, {0.5f, 0, -0.25f}, {-0.5f, 0.25f, 0}};
        const std::vector<std::pair<glm::dvec3, glm::dvec3>> looks = {
            {{0, 0, -1}, {0, 1, 0}}, {{1, 0, 0}, {0, 1, 0}}, {{0, -1, 0}, {0, 0, 1}}, {{0, 0, 1}, {1, 0, 0}}};
        for (std::size_t e = 0; e < eyes.size(); ++e)
            for (std::size_t l = 0; l < looks.size(); ++l) {
                StressCase c{"split-plane", "camera on planes " + std::to_string(e) + " look " + std::to_string(l),
                             triangles, {}, {}, {}};
                RayFan fan(c, eyes[e], true);
                addPinhole(fan, looks[l].first, looks[l].second, width, height);
                out.push_back(std::move(c));
            }
    }
    {
        // Axis-parallel and nearly axis-parallel rays: every direction whose components come
        // from {0, +-1e-30 (flushed to 0), +-1e-12, +-1e-7, +-1e-3, +-1}.
        const std::vector<Triangle> triangles = trianglesOf(roomWithShapes());
        const std::vector<double> values = {0.0, 1e-30, -1e-30, 1e-12, -1e-12, 1e-7, -1e-7, 1e-3, -1e-3, 1.0, -1.0};
        for (const glm::vec3& origin : {glm::vec3(0.25f, -0.5f, 0.125f), glm::vec3(0, 0, 0)}) {
            StressCase c{"split-plane", "axis-parallel from " + number(origin.x) + "," + number(origin.y) + "," +
                                            number(origin.z),
                         triangles, {}, {}, {}};
            RayFan fan(c, origin, true);
            for (double x : values)
                for (double y : values)
                    for (double z : values)
                        if (std::max({std::abs(x), std::abs(y), std::abs(z)}) >= 1e-3) fan.along({x, y, z});
            out.push_back(std::move(c));
        }
    }
    {
        // Grazing rays over a floor that fills the plane y = 0, from on it and just above it.
        std::vector<Mesh> meshes = {room(), grid({-1, 0, -1}, {2, 0, 0}, {0, 0, 2}, 16, 16),
                                    grid({-1.0f, -1.0f, 0.5f}, {2, 0, 0}, {0, 2.0f, 0.001f}, 8, 8)};
        const std::vector<Triangle> triangles = trianglesOf(meshes);
        const int azimuths = large ? 256 : 48;
        for (float height : {0.0f, 1e-6f, 1e-3f}) {
            StressCase c{"split-plane", "grazing at height " + number(height), triangles, {}, {}, {}};
            RayFan fan(c, glm::vec3(0.1f, height, 0.3f), true);
            for (double elevation : {0.0, 1e-7, -1e-7, 1e-6, -1e-6, 1e-5, -1e-5, 1e-4, -1e-4, 1e-3, -1e-3, 1e-2})
                for (int a = 0; a < azimuths; ++a) {
                    const double phi = 2.0 * M_PI * (a + 0.5 * random.uniform()) / azimuths;
                    fan.along({std::cos(phi), elevation, std::sin(phi)});
                }
            for (const glm::vec3& p : meshes[1].positions) fan.towards(glm::dvec3(p));
            out.push_back(std::move(c));
        }
    }
    return out;
}

// ---- degenerate geometry ---------------------------------------------------------------

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

}  // namespace

std::size_t StressCase::mustHitCount() const {
    return std::size_t(std::count(mustHit.begin(), mustHit.end(), std::uint8_t(1)));
}

std::vector<std::string> stressFamilies() { return {"watertight", "split-plane", "degenerate"}; }

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

std::vector<StressCase> splitPlaneCases(StressSize size, std::uint64_t seed) {
    Random random(seed + 1);
    return splitPlaneCasesImpl(size, random);
}

std::vector<StressCase> degenerateCases(StressSize size, std::uint64_t seed) {
    Random random(seed + 2);
    return degenerateCasesImpl(size, random);
}

StressCase determinismCase(StressSize size) {
    StressCase c{"determinism", "room with shapes from the centre", trianglesOf(roomWithShapes()), {}, {}, {}};
    RayFan fan(c, glm::vec3(0.0f), true);
    const bool large = size == StressSize::Large;
    addPinhole(fan, glm::normalize(glm::dvec3(0.3, -0.2, -1.0)), {0, 1, 0}, large ? 321 : 121, large ? 241 : 91);
    return c;
}

std::vector<StressCase> stressCases(const std::vector<std::string>& families, StressSize size, std::uint64_t seed) {
    std::vector<StressCase> out;
    for (const std::string& f : families) {
        std::vector<StressCase> part;
        if (f == "watertight") part = watertightCases(size, seed);
        else if (f == "split-plane") part = splitPlaneCases(size, seed);
        else if (f == "degenerate") part = degenerateCases(size, seed);
        else throw InputError("stress: unknown family '" + f + "' (choose from watertight, split-plane, degenerate)");
        for (StressCase& c : part) out.push_back(std::move(c));
    }
    return out;
}

}  // namespace dacrt
