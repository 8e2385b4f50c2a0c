// The stress suite's surface-rays family (docs/stability.md, "Rays that start on surfaces"):
// secondary rays made as the renderer makes them, from the hit a primary ray gives, and marked
// with the triangles the exact geometry says they cannot hit.
#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <optional>
#include <set>

#include "stress/case_building.hpp"
#include "core/camera.hpp"
#include "core/errors.hpp"
#include "core/random.hpp"
#include "cpu/secondary_rays.hpp"

namespace dacrt {
namespace {

using namespace stress;

// |d . n| below this (unit vectors, double) is not taken as a sign: the float32 direction and
// the double normal of float32 vertices are good to about 1e-16, the grazing rays' elevations
// start at 1e-7.
constexpr double kCertainSine = 1e-12;

// The reach of the origin offset (docs/stability.md, "Self-intersection"): moving the origin
// along the start triangle's normal clears another face's plane by at least half the move only
// where the two normals are at most 60 degrees apart; a face farther than this from the start
// point, four times the most the offset moves a coordinate (kOffsetSteps float32 steps of the
// largest coordinate magnitude at the start), is out of its reach.
constexpr double kClearedCosine = 0.5;
double offsetReach(const Triangle& t, const glm::dvec3& v) {
    double m = 0.0;
    for (const glm::vec3& p : {t.v0, t.v1, t.v2})
        m = std::max({m, double(std::abs(p.x)), double(std::abs(p.y)), double(std::abs(p.z))});
    m = std::max({m, std::abs(v.x), std::abs(v.y), std::abs(v.z)});
    return 4.0 * double(shared::kOffsetSteps) * std::ldexp(m, -23);
}

// The distance from p to the triangle (Ericson, "Real-Time Collision Detection", 5.1.5).
double distanceToTriangle(const glm::dvec3& p, const Triangle& t) {
    const glm::dvec3 a(t.v0), b(t.v1), c(t.v2);
    const glm::dvec3 ab = b - a, ac = c - a, ap = p - a;
    const double d1 = glm::dot(ab, ap), d2 = glm::dot(ac, ap);
    if (d1 <= 0.0 && d2 <= 0.0) return glm::length(ap);
    const glm::dvec3 bp = p - b;
    const double d3 = glm::dot(ab, bp), d4 = glm::dot(ac, bp);
    if (d3 >= 0.0 && d4 <= d3) return glm::length(bp);
    const double vc = d1 * d4 - d3 * d2;
    if (vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0) return glm::length(ap - ab * (d1 / (d1 - d3)));
    const glm::dvec3 cp = p - c;
    const double d5 = glm::dot(ab, cp), d6 = glm::dot(ac, cp);
    if (d6 >= 0.0 && d5 <= d6) return glm::length(cp);
    const double vb = d5 * d2 - d1 * d6;
    if (vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0) return glm::length(ap - ac * (d2 / (d2 - d6)));
    const double va = d3 * d6 - d5 * d4;
    if (va <= 0.0 && d4 - d3 >= 0.0 && d5 - d6 >= 0.0)
        return glm::length(bp - (c - b) * ((d4 - d3) / ((d4 - d3) + (d5 - d6))));
    const double denominator = 1.0 / (va + vb + vc);
    return glm::length(ap - ab * (vb * denominator) - ac * (vc * denominator));
}

// The sign of n . (x - a), n = (b - a) x (c - a) the triangle's winding normal, where double
// precision certifies it: Shewchuk's orient3d with his first error bound (valid for any double
// inputs). 0 where x lies exactly in the plane: it is a vertex, or all four points share a
// coordinate. nullopt where neither is certain.
std::optional<int> certainSide(const glm::vec3& a, const glm::vec3& b, const glm::vec3& c, const glm::vec3& x) {
    if (x == a || x == b || x == c) return 0;
    for (int k = 0; k < 3; ++k)
        if (a[k] == b[k] && a[k] == c[k] && a[k] == x[k]) return 0;
    const double adx = double(a.x) - x.x, ady = double(a.y) - x.y, adz = double(a.z) - x.z;
    const double bdx = double(b.x) - x.x, bdy = double(b.y) - x.y, bdz = double(b.z) - x.z;
    const double cdx = double(c.x) - x.x, cdy = double(c.y) - x.y, cdz = double(c.z) - x.z;
    const double bc = bdx * cdy - cdx * bdy, ca = cdx * ady - adx * cdy, ab = adx * bdy - bdx * ady;
    const double det = adz * bc + bdz * ca + cdz * ab;
    const double permanent = (std::abs(bdx * cdy) + std::abs(cdx * bdy)) * std::abs(adz) +
                             (std::abs(cdx * ady) + std::abs(adx * cdy)) * std::abs(bdz) +
                             (std::abs(adx * bdy) + std::abs(bdx * ady)) * std::abs(cdz);
    const double epsilon = 0x1p-53;
    const double bound = (7.0 + 56.0 * epsilon) * epsilon * permanent;
    // orient3d is positive where x lies on the side opposite the winding normal.
    if (det > bound) return -1;
    if (-det > bound) return 1;
    return std::nullopt;
}

// Whether every edge of a closed mesh is used once in each direction: then the winding normals
// all face the same side, which the marks at shared edges and vertices rely on.
bool consistentlyWound(const Mesh& m) {
    using Corner = std::array<float, 3>;
    std::map<std::pair<Corner, Corner>, int> directed;
    auto corner = [&](std::uint32_t i) { return Corner{m.positions[i].x, m.positions[i].y, m.positions[i].z}; };
    for (std::size_t i = 0; i + 2 < m.indices.size(); i += 3)
        for (int e = 0; e < 3; ++e) ++directed[{corner(m.indices[i + e]), corner(m.indices[i + (e + 1) % 3])}];
    return std::all_of(directed.begin(), directed.end(), [&](const auto& entry) {
        const auto reverse = directed.find({entry.first.second, entry.first.first});
        return entry.second == 1 && reverse != directed.end() && reverse->second == 1;
    });
}

// +1 where the winding normals of a closed, consistently wound mesh point out (its signed
// volume is positive), -1 where they point in.
double outwardSide(const Mesh& m) {
    double volume = 0.0;
    for (std::size_t i = 0; i + 2 < m.indices.size(); i += 3)
        volume += glm::dot(glm::dvec3(m.positions[m.indices[i]]), glm::cross(glm::dvec3(m.positions[m.indices[i + 1]]),
                                                                            glm::dvec3(m.positions[m.indices[i + 2]])));
    return volume > 0.0 ? 1.0 : -1.0;
}

// A closed triangular prism along z whose cross-section has a 20-degree apex: a sharp convex
// edge from outside, an acute concave crease from inside.
Mesh knife() {
    const float w = float(std::tan(M_PI / 18.0));  // half the 20-degree apex angle
    Mesh m;
    m.name = "knife";
    // Apex, upper and lower corner at z = -1, then the same at z = +1.
    m.positions = {{1, 0, -1}, {-1, w, -1}, {-1, -w, -1}, {1, 0, 1}, {-1, w, 1}, {-1, -w, 1}};
    m.indices = {0, 2, 1,  3, 4, 5,  0, 1, 4, 0, 4, 3,  1, 2, 5, 1, 5, 4,  2, 0, 3, 2, 3, 5};
    return m;
}

// What a case's rays are traced against: the triangles and their unit winding normals.
struct Geometry {
    std::vector<Triangle> triangles;
    std::vector<glm::dvec3> normals;
    double scale = 1.0;
};

Geometry geometryOf(const std::vector<Triangle>& triangles, double scale) {
    Geometry g{triangles, {}, scale};
    for (const Triangle& t : triangles) {
        const glm::dvec3 n = glm::cross(glm::dvec3(t.v1) - glm::dvec3(t.v0), glm::dvec3(t.v2) - glm::dvec3(t.v0));
        g.normals.push_back(glm::length(n) > 0.0 ? glm::normalize(n) : n);
    }
    return g;
}

// One face of a crease: a parallelogram, the ids of its triangles, its unit normal towards
// the open wedge, and the corner and sides that bound it.
struct CreaseFace {
    std::string name;
    std::vector<std::uint32_t> triangles;
    glm::dvec3 normal{0.0};
    glm::dvec3 corner{0.0}, across{0.0}, along{0.0};  // points corner + s across + z along, s, z in [0, 1]
};

// Where a ray starts: the point V the primary ray is aimed at, exactly on the triangles it lists
// (a vertex, a point of a shared edge, a point inside one triangle), and where the eye is.
struct StartPoint {
    std::string where;
    glm::dvec3 point{0.0};
    std::vector<std::uint32_t> containing;
    glm::dvec3 toEye{0.0};  // unit
    // +1 (-1): the primary ray must meet the winding normals' front (back) side; a start whose
    // eye ended up on the other side is not the start meant.
    double side = 1.0;
    // Crease starts: the faces V lies on or in front of.
    std::vector<const CreaseFace*> faces;
    // Rays that leave every containing triangle to the front must hit (V inside a closed mesh).
    bool insideClosedMesh = false;
};

// The closest hit of a ray over every triangle, as brute force finds it: the primary hit that
// the renderer starts secondary rays from.
Hit closestHit(const std::vector<Triangle>& triangles, const Ray& ray) {
    Hit best{ray.tmax, kMissPrim, 0.0f, 0.0f};
    for (std::size_t i = 0; i < triangles.size(); ++i) {
        const Triangle& t = triangles[i];
        const shared::TriangleHit h = shared::intersectWatertight(ray, t.v0, t.v1, t.v2, t.cullBackFace != 0u);
        if (h.hit && h.t > ray.tmin && shared::hitPrecedes(h.t, std::uint32_t(i), best.t, best.prim))
            best = Hit{h.t, std::uint32_t(i), h.u, h.v};
    }
    return best;
}

// Builds one case's rays from start points and marks each: must-hit, and the triangles it
// rules out.
class SurfaceRayMaker {
public:
    SurfaceRayMaker(StressCase& c, const Geometry& g, Random& random, StressSize size)
        : case_(c), geometry_(g), random_(random), large_(size == StressSize::Large),
          seed_(std::uint32_t(random.index(1u << 30))) {}

    // The primary ray from the eye to V, its closest hit, then the secondary rays from it.
    // Starts whose primary hit lands elsewhere (another surface in front, a neighbouring
    // triangle where V is not on it, the other side of the surface) make no rays: V would not
    // be their start point. (At the small size: a fifth of the knife's starts from inside, whose
    // tilted eye can leave through the thin apex, an eighth of the 30-degree crease's, few
    // elsewhere.)
    void shoot(const StartPoint& start, const std::vector<ShadowLight>& lights = {}) {
        const glm::vec3 eye(start.point + start.toEye * (0.05 * geometry_.scale));
        const Ray primary = makeRay(eye, start.point - glm::dvec3(eye));
        const Hit hit = closestHit(geometry_.triangles, primary);
        if (std::find(start.containing.begin(), start.containing.end(), hit.prim) == start.containing.end()) return;
        const shared::SurfaceSample surface = shared::surfaceOfHit(primary, hit, geometry_.triangles[hit.prim]);
        if (!surface.valid) return;
        const std::uint32_t t = hit.prim;
        const double side = glm::dot(geometry_.normals[t], glm::dvec3(surface.normal)) > 0.0 ? 1.0 : -1.0;
        if (side != start.side) return;
        Shot shot{start, t, side, surface, geometry_.normals[t] * side,
                  offsetReach(geometry_.triangles[t], start.point), false, {}};
        shot.startOfMarks.fill(kNoSurfaceStart);
        // A face the offset may not clear, within its reach of V (through V or not), may end up
        // between the origin and the mesh's inside: a ray from V inside a closed mesh must then
        // hit only in exact geometry (a ray grazing that face from behind it meets its plane
        // beyond its end).
        for (std::size_t i = 0; i < geometry_.triangles.size() && start.insideClosedMesh; ++i)
            shot.nearUnclearedFace = shot.nearUnclearedFace ||
                                     (!cleared(shot, geometry_.normals[i] * side) &&
                                      distanceToTriangle(start.point, geometry_.triangles[i]) <= shot.reach);

        // The renderer's ambient occlusion: cosine-distributed rays, whole ones and segments.
        const int occlusion = large_ ? 24 : 8;
        for (int k = 0; k < occlusion; ++k) {
            const float length = k % 2 == 0 ? kNoHitT : float(0.5 * geometry_.scale);
            add(shot, shared::occlusionRay(surface, slot_++, seed_, length));
        }
        // Grazing rays: elevations above the start triangle's exact plane from 1e-7 rad.
        const glm::dvec3& n = shot.normal;
        const glm::dvec3 u = glm::normalize(glm::cross(n, random_.onSphere()));
        const glm::dvec3 v = glm::cross(n, u);
        const int azimuths = large_ ? 8 : 3;
        for (double elevation : {1e-7, 1e-6, 1e-5, 1e-4, 1e-3, 1e-2, 0.2}) {
            for (int a = 0; a < azimuths; ++a) {
                const double phi = 2.0 * M_PI * (a + random_.uniform()) / azimuths;
                const glm::dvec3 d =
                    std::cos(elevation) * (std::cos(phi) * u + std::sin(phi) * v) + std::sin(elevation) * n;
                add(shot, {shared::segmentRay(surface.origin, glm::vec3(d), kNoHitT), true});
            }
        }
        for (const ShadowLight& light : lights) add(shot, shared::shadowRay(surface, light));
    }

private:
    static constexpr unsigned kBehindStartPlane = 1, kAtStart = 2, kFace = 4;  // then 8 for a second face

    struct Shot {
        const StartPoint& start;
        std::uint32_t triangle;  // the primary hit's
        double side;             // +1: the winding normals face the primary ray's side
        const shared::SurfaceSample& surface;
        glm::dvec3 normal;       // the start triangle's unit normal, on the ray's side
        double reach;            // offsetReach at the start
        bool nearUnclearedFace;  // see shoot()
        std::array<std::uint32_t, 16> startOfMarks;  // the case's start entry per set of marks
    };

    // Triangles with every vertex behind or on the plane of triangle t, its normal taken on
    // `side`, as double precision certifies it.
    const std::vector<std::uint32_t>& behindPlaneOf(std::uint32_t t, double side) {
        std::vector<std::uint32_t>& out = behind_[{t, side > 0.0}];
        if (!out.empty()) return out;
        const Triangle& p = geometry_.triangles[t];
        for (std::size_t i = 0; i < geometry_.triangles.size(); ++i) {
            const Triangle& x = geometry_.triangles[i];
            bool behind = true;
            for (const glm::vec3& corner : {x.v0, x.v1, x.v2}) {
                const std::optional<int> s = certainSide(p.v0, p.v1, p.v2, corner);
                behind = behind && s && double(*s) * side <= 0.0;
            }
            if (behind) out.push_back(std::uint32_t(i));
        }
        return out;
    }

    // Marks a ray from this shot: must-hit, and the triangles it rules out (docs/stability.md,
    // "Self-intersection"): each lies on or behind a plane through V that the ray leaves, so for
    // t > 0 the ray's points lie strictly in front of it.
    void add(Shot& shot, const shared::GeneratedRay& generated) {
        if (!generated.traced) return;
        const Ray& r = generated.ray;
        const glm::dvec3 d = glm::normalize(glm::dvec3(r.dir));
        const StartPoint& start = shot.start;
        unsigned marks = 0;
        // The start triangle's plane: with a convex mesh seen from outside, every triangle.
        if (glm::dot(d, shot.normal) > kCertainSine) marks |= kBehindStartPlane;
        // Each triangle containing V (V need only lie in its plane), when the ray leaves all of
        // them to the front, so that it enters no solid behind one of them at V.
        const bool leavesAll = std::all_of(start.containing.begin(), start.containing.end(), [&](std::uint32_t x) {
            return glm::dot(d, geometry_.normals[x] * shot.side) > kCertainSine;
        });
        if (leavesAll) marks |= kAtStart;
        bool mustHit = leavesAll && start.insideClosedMesh && !shot.nearUnclearedFace && r.tmax == kNoHitT;
        for (std::size_t k = 0; k < start.faces.size(); ++k) {
            // V lies on or in front of the face: a ray moving away from its plane never meets it;
            // one crossing it well inside must hit it (only the crease is in the scene).
            const CreaseFace& f = *start.faces[k];
            const double height = glm::dot(start.point - f.corner, f.normal);
            const double towards = glm::dot(d, f.normal);
            if (height < 0.0 || !(cleared(shot, f.normal) || height > shot.reach)) continue;
            if (towards > kCertainSine) marks |= kFace << k;
            else if (towards < -0.02 && height > 0.0 && leavesAll)
                mustHit = mustHit || crossesWellInside(f, start.point, d, height / -towards, r, shot);
        }
        case_.rays.push_back(r);
        case_.mustHit.push_back(mustHit ? 1 : 0);
        case_.startOf.push_back(marks ? startWith(shot, marks) : kNoSurfaceStart);
    }

    // Whether the offset, which moves the origin along the start triangle's normal, clears a
    // plane of this normal (see kClearedCosine).
    static bool cleared(const Shot& shot, const glm::dvec3& normal) {
        return glm::dot(normal, shot.normal) >= kClearedCosine;
    }

    // The case's start entry of a shot and a set of marks: the union of the triangles they rule
    // out, made on first use.
    std::uint32_t startWith(Shot& shot, unsigned marks) {
        std::uint32_t& entry = shot.startOfMarks[marks];
        if (entry != kNoSurfaceStart) return entry;
        std::set<std::uint32_t> ruledOut;
        std::vector<std::string> reasons;
        if (marks & kBehindStartPlane) {
            const std::vector<std::uint32_t>& behind = behindPlaneOf(shot.triangle, shot.side);
            ruledOut.insert(behind.begin(), behind.end());
            reasons.push_back("behind the start plane");
        }
        if (marks & kAtStart) {
            // Those whose plane the offset clears: the others are out of its reach.
            for (std::uint32_t x : shot.start.containing)
                if (cleared(shot, geometry_.normals[x] * shot.side)) ruledOut.insert(x);
            reasons.push_back("at the start");
        }
        for (std::size_t k = 0; k < shot.start.faces.size(); ++k)
            if (marks & (kFace << k)) {
                ruledOut.insert(shot.start.faces[k]->triangles.begin(), shot.start.faces[k]->triangles.end());
                reasons.push_back("the " + shot.start.faces[k]->name);
            }
        std::string where = shot.start.where + " (rules out: ";
        for (std::size_t i = 0; i < reasons.size(); ++i) where += (i ? ", " : "") + reasons[i];
        entry = std::uint32_t(case_.starts.size());
        case_.starts.push_back({where + ")", shot.normal, {ruledOut.begin(), ruledOut.end()}});
        return entry;
    }

    // Whether the ray from V along d (unit), V in front of the face and on the floor, which the
    // ray leaves, meets the face within its segment and inside the face away from its far side
    // and its ends: by a margin that covers the real origin's distance from V. (It meets the
    // face's plane on the open wedge's side of the floor, so the edge it shares with the floor
    // needs no margin: a watertight tracer gives that edge to one face or the other.)
    bool crossesWellInside(const CreaseFace& f, const glm::dvec3& v, const glm::dvec3& d, double distance, const Ray& r,
                           const Shot& shot) const {
        if (r.tmax != kNoHitT && distance > 0.999 * double(r.tmax) * glm::length(glm::dvec3(r.dir))) return false;
        const glm::dvec3 p = v + d * distance - f.corner;
        const double sine = -glm::dot(d, f.normal);
        const double margin = 0.02 * geometry_.scale + 2.0 * glm::length(glm::dvec3(shot.surface.origin) - v) / sine;
        const double width = glm::length(f.across), length = glm::length(f.along);
        const double s = glm::dot(p, f.across) / width, z = glm::dot(p, f.along) / length;
        return s < width - margin && z > margin && z < length - margin;
    }

    StressCase& case_;
    const Geometry& geometry_;
    Random& random_;
    bool large_;
    std::uint32_t seed_;
    std::uint32_t slot_ = 0;
    std::map<std::pair<std::uint32_t, bool>, std::vector<std::uint32_t>> behind_;
};

// The triangles that have every one of the corners as a vertex.
std::vector<std::uint32_t> trianglesWith(const std::vector<Triangle>& triangles,
                                         const std::vector<glm::vec3>& corners) {
    std::vector<std::uint32_t> out;
    for (std::size_t i = 0; i < triangles.size(); ++i) {
        const Triangle& t = triangles[i];
        auto isCorner = [&](const glm::vec3& p) { return p == t.v0 || p == t.v1 || p == t.v2; };
        if (std::all_of(corners.begin(), corners.end(), isCorner)) out.push_back(std::uint32_t(i));
    }
    return out;
}

// The eye direction at a start: the mean of the containing triangles' normals on the wanted
// side, tilted at random so that primary rays arrive at several angles.
glm::dvec3 eyeDirection(const Geometry& g, const std::vector<std::uint32_t>& containing, double side, Random& random) {
    glm::dvec3 mean(0.0);
    for (std::uint32_t t : containing) mean += g.normals[t] * side;
    return glm::normalize(glm::normalize(mean) + random.onSphere() * 0.3);
}

// Vertices, edge points and face points of a closed mesh, seen from outside or inside.
void addMeshCase(std::vector<StressCase>& out, const std::string& label, const Mesh& mesh, double scale, bool inside,
                 StressSize size, Random& random) {
    const bool large = size == StressSize::Large;
    StressCase c{"surface-rays", label + (inside ? " inside" : " outside"), trianglesOf({mesh}), {}, {}, {}};
    const Geometry g = geometryOf(c.triangles, scale);
    const double side = outwardSide(mesh) * (inside ? -1.0 : 1.0);
    SurfaceRayMaker maker(c, g, random, size);
    auto start = [&](const std::string& where, const glm::dvec3& point, const std::vector<std::uint32_t>& containing) {
        StartPoint s{where, point, containing, eyeDirection(g, containing, side, random), side, {}, inside};
        maker.shoot(s);
    };
    const int count = large ? 40 : 10;
    for (int i = 0; i < count; ++i) {
        const glm::vec3 p = mesh.positions[random.index(mesh.positions.size())];
        start("vertex " + number(p.x) + "," + number(p.y) + "," + number(p.z), glm::dvec3(p),
              trianglesWith(c.triangles, {p}));
    }
    const std::vector<std::pair<std::uint32_t, std::uint32_t>> edges = edgesOf(mesh);
    for (int i = 0; i < count; ++i) {
        const auto [a, b] = edges[random.index(edges.size())];
        const double lambda = i % 2 == 0 ? 0.5 : random.uniform(0.01, 0.99);
        const glm::vec3 pa = mesh.positions[a], pb = mesh.positions[b];
        start("edge at " + number(lambda), glm::dvec3(pa) + lambda * (glm::dvec3(pb) - glm::dvec3(pa)),
              trianglesWith(c.triangles, {pa, pb}));
    }
    for (int i = 0; i < count; ++i) {
        const std::uint32_t t = std::uint32_t(random.index(c.triangles.size()));
        // Well inside, and a third of them 1e-5 of the way from an edge.
        const double b1 = random.uniform(0.05, 0.9);
        const double b2 = i % 3 == 0 ? 1e-5 : random.uniform(0.05, 0.95 - b1);
        const Triangle& tri = c.triangles[t];
        start("face at " + number(b1) + "," + number(b2),
              (1.0 - b1 - b2) * glm::dvec3(tri.v0) + b1 * glm::dvec3(tri.v1) + b2 * glm::dvec3(tri.v2), {t});
    }
    out.push_back(std::move(c));
}

// Two faces meeting at a concave edge with an opening angle, each a parallelogram of 4 x 1
// quads: points on the edge (at its vertices and between them) and on the first face at
// distances from it of 1 to 4096 float32 steps and a tenth of the face; rays into the open
// wedge, and rays and shadow rays towards the other face.
void addCreaseCase(std::vector<StressCase>& out, double angleDegrees, double scale, const glm::dvec3& shift,
                   const std::string& label, StressSize size, Random& random) {
    const bool large = size == StressSize::Large;
    const double angle = glm::radians(angleDegrees);
    const glm::dvec3 wall(std::cos(angle), std::sin(angle), 0.0);
    auto at = [&](const glm::dvec3& unit) { return glm::vec3(unit * scale + shift); };
    auto atPoint = [&](const glm::dvec3& unit) { return glm::dvec3(at(unit)); };
    const int rows = 4;
    StressCase c{"surface-rays", "crease " + number(angleDegrees) + "deg " + label, {}, {}, {}, {}};
    CreaseFace floor, other;
    floor.name = "floor";
    other.name = "wall";
    for (int k = 0; k < rows; ++k) {
        const double z0 = -1.0 + 2.0 * k / rows, z1 = -1.0 + 2.0 * (k + 1) / rows;
        const glm::vec3 e0 = at({0, 0, z0}), e1 = at({0, 0, z1});
        const glm::vec3 f0 = at({1, 0, z0}), f1 = at({1, 0, z1});
        const glm::vec3 g0 = at(wall + glm::dvec3(0, 0, z0)), g1 = at(wall + glm::dvec3(0, 0, z1));
        // Winding normals towards the open wedge on both faces.
        for (const Triangle& t : {Triangle{e0, 0, e1, 0, f1, 0}, Triangle{e0, 0, f1, 0, f0, 0}}) {
            floor.triangles.push_back(std::uint32_t(c.triangles.size()));
            c.triangles.push_back(t);
        }
        for (const Triangle& t : {Triangle{e0, 0, g1, 0, e1, 0}, Triangle{e0, 0, g0, 0, g1, 0}}) {
            other.triangles.push_back(std::uint32_t(c.triangles.size()));
            c.triangles.push_back(t);
        }
    }
    const Geometry g = geometryOf(c.triangles, scale);
    const glm::dvec3 edge0 = atPoint({0, 0, -1}), edge1 = atPoint({0, 0, 1});
    for (CreaseFace* f : {&floor, &other}) {
        f->normal = g.normals[f->triangles[0]];
        f->corner = edge0;
        f->along = edge1 - edge0;
    }
    floor.across = atPoint({1, 0, -1}) - edge0;
    other.across = atPoint(wall + glm::dvec3(0, 0, -1)) - edge0;
    const glm::dvec3 bisector = glm::normalize(floor.normal + other.normal);

    SurfaceRayMaker maker(c, g, random, size);
    const int perDistance = large ? 12 : 4;
    std::vector<glm::dvec3> edgeVertices;  // the edge's inner vertices
    for (int k = 1; k < rows; ++k) edgeVertices.push_back(atPoint({0, 0, -1.0 + 2.0 * k / rows}));
    for (double distance : {0.0, 1.0, 16.0, 256.0, 4096.0, -0.1}) {
        std::vector<StartPoint> starts;
        if (distance == 0.0) {
            for (const glm::dvec3& v : edgeVertices)
                starts.push_back(
                    {"crease vertex", v, trianglesWith(c.triangles, {glm::vec3(v)}), {}, 1.0, {&floor, &other}});
        }
        for (int i = 0; i < perDistance; ++i) {
            const double z = random.uniform(-0.9, 0.9);
            const glm::dvec3 onEdge = atPoint({0, 0, z});
            // Float32 steps at the point (of its largest coordinate), or (negative) a part of the face.
            const double m = std::max({std::abs(onEdge.x), std::abs(onEdge.y), std::abs(onEdge.z)});
            const double away = distance >= 0.0 ? distance * std::ldexp(1.0, std::ilogb(m) - 23) : -distance * scale;
            StartPoint s{"", onEdge + glm::normalize(floor.across) * away, {}, {}, 1.0, {}};
            if (away == 0.0) {
                // A point of the shared edge of a row (float32 rounding keeps it on the edge: the
                // edge varies in z alone).
                const int row = std::min(rows - 1, int((z + 1.0) * rows / 2.0));
                s.containing = trianglesWith(c.triangles, {at({0, 0, -1.0 + 2.0 * row / rows}),
                                                           at({0, 0, -1.0 + 2.0 * (row + 1) / rows})});
                s.where = "crease edge";
                s.faces = {&floor, &other};
            } else {
                // The floor triangle V lies inside: the one along the edge, unless V is past its diagonal.
                for (std::uint32_t t : floor.triangles) {
                    const Triangle& tri = c.triangles[t];
                    const glm::dvec3 a(tri.v0), b(tri.v1), cc(tri.v2);
                    const glm::dvec3 n = glm::cross(b - a, cc - a);
                    const double w0 = glm::dot(glm::cross(b - s.point, cc - s.point), n) / glm::dot(n, n);
                    const double w1 = glm::dot(glm::cross(cc - s.point, a - s.point), n) / glm::dot(n, n);
                    if (w0 > 1e-9 && w1 > 1e-9 && 1.0 - w0 - w1 > 1e-9) s.containing = {t};
                }
                if (s.containing.empty()) continue;  // on a diagonal: not one triangle's point
                s.where = "crease " +
                          (distance >= 0.0 ? number(distance) + " steps" : number(-distance) + " of the face") +
                          " from the edge";
                s.faces = {&other};
            }
            s.where += " at z " + number(z);
            starts.push_back(s);
        }
        for (StartPoint& s : starts) {
            s.toEye = glm::normalize(bisector + random.onSphere() * 0.3);
            // Point lights just behind the other face: shadow rays that the face must stop.
            std::vector<ShadowLight> lights;
            for (int k = 0; k < 3 && s.faces.size() == 1; ++k) {
                // Two statements: the operands of + are unsequenced, and every compiler must draw alike.
                const double across = random.uniform(0.3, 0.7);
                const glm::dvec3 onWall = wall * across + glm::dvec3(0, 0, random.uniform(-0.6, 0.6));
                ShadowLight light{};
                light.type = shared::kLightPoint;
                light.position = at(onWall - glm::dvec3(std::sin(angle), -std::cos(angle), 0.0) * 0.1);
                lights.push_back(light);
            }
            maker.shoot(s, lights);
        }
    }
    out.push_back(std::move(c));
}

// Whether float32 resolves a shape of size `scale` at `offset`: thousands of units in the last
// place across it (the degenerate family's rule).
bool resolvable(double scale, const glm::dvec3& offset) {
    const double magnitude = std::max({std::abs(offset.x), std::abs(offset.y), std::abs(offset.z)}) + 2.0 * scale;
    return scale >= 4096.0 * std::ldexp(1.0, std::ilogb(magnitude) - 23);
}

}  // namespace

std::vector<StressCase> surfaceCases(StressSize size, std::uint64_t seed) {
    Random random(seed + 3);
    const bool large = size == StressSize::Large;
    const std::vector<std::pair<std::string, Mesh>> meshes = {
        {"icosphere", icosphere({0, 0, 0}, 1.0f, large ? 3 : 2)},
        {"cube", box({-1, -1, -1}, {1, 1, 1})},
        {"torus", torus({0, 0, 0}, 1.0f, 0.3f, large ? 48 : 16, large ? 16 : 8)},
        {"knife", knife()}};
    for (const auto& [name, mesh] : meshes)
        if (!consistentlyWound(mesh)) throw InternalError("stress: the " + name + " mesh is not consistently wound");
    const glm::dvec3 direction(1.0, -0.7, 0.4);
    std::vector<StressCase> closest;
    for (double scale : {1e-4, 1e-2, 1.0, 1e2, 1e4, 1e6})
        for (double offset : {0.0, 1e2, 1e4, 1e6}) {
            const glm::dvec3 shift = direction * offset;
            if (!resolvable(scale, shift)) continue;
            const std::string label = "scale " + number(scale) + " offset " + number(offset);
            for (const auto& [name, unit] : meshes) {
                Mesh placed = unit;
                for (glm::vec3& p : placed.positions) p = glm::vec3(glm::dvec3(p) * scale + shift);
                for (bool inside : {false, true})
                    addMeshCase(closest, name + " " + label, placed, scale, inside, size, random);
            }
            for (double angle : {30.0, 90.0, 150.0}) addCreaseCase(closest, angle, scale, shift, label, size, random);
        }
    // The same rays as closest-hit queries and as any-hit queries (shadow and occlusion rays).
    std::vector<StressCase> out;
    for (StressCase& c : closest) {
        StressCase any = c;
        any.name += " any";
        any.query = HitQuery::Any;
        c.name += " closest";
        out.push_back(std::move(c));
        out.push_back(std::move(any));
    }
    return out;
}

}  // namespace dacrt
