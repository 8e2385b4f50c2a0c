#include "oracle/reference_tracer.hpp"

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>

#include <unistd.h>

#include "core/atomic_file.hpp"
#include "core/errors.hpp"
#include "cpu/option_predicates.hpp"

namespace dacrt {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr std::uint32_t kLeafRays = 8, kLeafTriangles = 8, kMaxDepth = 64;

struct BoxF64 {
    glm::dvec3 lo{kInf}, hi{-kInf};
};

// Entry and exit of the ray through a box, in float64. A zero direction component keeps the
// ray inside the slab iff its origin is.
bool slab(const RayF64& r, const BoxF64& b, double& tNear, double& tFar) {
    tNear = -kInf;
    tFar = kInf;
    for (int a = 0; a < 3; ++a) {
        if (r.dir[a] == 0.0) {
            if (r.origin[a] < b.lo[a] || r.origin[a] > b.hi[a]) return false;
            continue;
        }
        const double t0 = (b.lo[a] - r.origin[a]) / r.dir[a], t1 = (b.hi[a] - r.origin[a]) / r.dir[a];
        tNear = std::max(tNear, std::min(t0, t1));
        tFar = std::min(tFar, std::max(t0, t1));
    }
    return tNear <= tFar;
}

class ReferenceTraversal {
public:
    ReferenceTraversal(const std::vector<Triangle>& triangles, const std::vector<RayF64>& rays,
                       std::vector<ReferenceHit>& hits, double margin)
        : triangles_(triangles), rays_(rays), hits_(hits), margin_(margin) {}

    // Rays of one octant (the same direction sign on every axis, zero counting as positive):
    // visiting the child on the low side first is then front to back for every one of them,
    // wherever their origins are.
    void run(const BoxF64& sceneBox, std::vector<std::uint32_t> rayIds) {
        rayIds_ = std::move(rayIds);
        if (rayIds_.empty()) return;
        triIds_.resize(triangles_.size());
        for (std::uint32_t i = 0; i < triIds_.size(); ++i) triIds_[i] = i;
        std::size_t terminated = 0;
        const std::size_t live = filterRays(widen(sceneBox), 0, rayIds_.size());
        node(sceneBox, terminated, live, 0, triIds_.size(), 0, 0);
    }

private:
    // Wider than any float64 rounding of a slab or hit parameter by many orders of magnitude,
    // so that a hit inside a box is always inside its widened copy (docs/benchmarks.md).
    BoxF64 widen(const BoxF64& b) const { return {b.lo - glm::dvec3(margin_), b.hi + glm::dvec3(margin_)}; }

    std::size_t filterRays(const BoxF64& cell, std::size_t begin, std::size_t end) {
        auto first = std::partition(rayIds_.begin() + std::ptrdiff_t(begin), rayIds_.begin() + std::ptrdiff_t(end),
                                    [&](std::uint32_t id) {
                                        double tNear = 0.0, tFar = 0.0;
                                        if (!slab(rays_[id], cell, tNear, tFar)) return false;
                                        return tFar >= rays_[id].tmin && tNear <= hits_[id].t;
                                    });
        return std::size_t(first - rayIds_.begin());
    }

    std::size_t filterTriangles(const BoxF64& cell, std::size_t begin, std::size_t end) {
        auto first = std::partition(triIds_.begin() + std::ptrdiff_t(begin), triIds_.begin() + std::ptrdiff_t(end),
                                    [&](std::uint32_t id) {
                                        const Triangle& t = triangles_[id];
                                        for (int a = 0; a < 3; ++a) {
                                            const double lo = std::min({t.v0[a], t.v1[a], t.v2[a]});
                                            const double hi = std::max({t.v0[a], t.v1[a], t.v2[a]});
                                            if (hi < cell.lo[a] || lo > cell.hi[a]) return false;
                                        }
                                        return true;
                                    });
        return std::size_t(first - triIds_.begin());
    }

    void node(const BoxF64& box, std::size_t& terminated, std::size_t rayEnd, std::size_t triBegin,
              std::size_t triEnd, std::uint32_t depth, std::uint32_t stalls) {
        if (terminated >= rayEnd || triBegin >= triEnd) return;
        const glm::dvec3 e = box.hi - box.lo;
        const int axis = e.x >= e.y && e.x >= e.z ? 0 : (e.y >= e.z ? 1 : 2);
        const double split = 0.5 * (box.lo[axis] + box.hi[axis]);
        if (rayEnd - terminated < kLeafRays || triEnd - triBegin < kLeafTriangles || depth >= kMaxDepth ||
            stalls >= 3 || !(split > box.lo[axis] && split < box.hi[axis])) {
            leaf(box, terminated, rayEnd, triBegin, triEnd);
            return;
        }
        BoxF64 low = box, high = box;
        low.hi[axis] = split;
        high.lo[axis] = split;
        const bool lowFirst = rays_[rayIds_[terminated]].dir[axis] >= 0.0;
        for (const BoxF64* child : {lowFirst ? &low : &high, lowFirst ? &high : &low}) {
            const BoxF64 cell = widen(*child);
            const std::size_t childRays = filterRays(cell, terminated, rayEnd);
            if (childRays == terminated) continue;
            const std::size_t childTris = filterTriangles(cell, triBegin, triEnd);
            const bool stalled = childRays == rayEnd && childTris == triEnd;
            node(*child, terminated, childRays, triBegin, childTris, depth + 1, stalled ? stalls + 1 : 0);
        }
    }

    void leaf(const BoxF64& box, std::size_t& terminated, std::size_t rayEnd, std::size_t triBegin,
              std::size_t triEnd) {
        const BoxF64 cell = widen(box);
        for (std::size_t k = terminated; k < rayEnd; ++k) {
            const std::uint32_t id = rayIds_[k];
            const RayF64& ray = rays_[id];
            ReferenceHit best = hits_[id];
            for (std::size_t j = triBegin; j < triEnd; ++j) {
                const std::uint32_t prim = triIds_[j];
                const Triangle& t = triangles_[prim];
                const TriangleHitF64 h = intersectWatertightF64(ray, t.v0, t.v1, t.v2, t.cullBackFace != 0u);
                if (h.hit && h.t > ray.tmin && (h.t < best.t || (h.t == best.t && prim < best.prim)))
                    best = ReferenceHit{h.t, prim};
            }
            hits_[id] = best;
            // Final once the hit lies before the ray leaves this cell: every cell the ray
            // crossed before that point has been visited (front to back).
            double tNear = 0.0, tFar = 0.0;
            if (best.prim != kMissPrim && slab(ray, cell, tNear, tFar) && best.t <= tFar) {
                std::swap(rayIds_[k], rayIds_[terminated]);
                ++terminated;
            }
        }
    }

    const std::vector<Triangle>& triangles_;
    const std::vector<RayF64>& rays_;
    std::vector<ReferenceHit>& hits_;
    double margin_;
    std::vector<std::uint32_t> rayIds_;
    std::vector<std::uint32_t> triIds_;
};

void checkRays(const std::vector<Ray>& rays) {
    for (const Ray& r : rays)
        if (!std::isfinite(r.origin.x) || !std::isfinite(r.origin.y) || !std::isfinite(r.origin.z) ||
            !(r.dir.x != 0.0f || r.dir.y != 0.0f || r.dir.z != 0.0f))
            throw InputError("reference tracer: a ray has a non-finite origin or a zero direction");
}

}  // namespace

std::vector<ReferenceHit> traceReference(const std::vector<Triangle>& triangles, const std::vector<Ray>& rays,
                                         ThreadPool& pool) {
    checkRays(rays);
    std::vector<ReferenceHit> hits(rays.size(), ReferenceHit{kInf, kMissPrim});
    if (triangles.empty() || rays.empty()) return hits;
    std::vector<RayF64> wide(rays.size());
    for (std::size_t i = 0; i < rays.size(); ++i) wide[i] = toF64(rays[i]);
    BoxF64 box;
    double magnitude = 0.0;
    for (const Triangle& t : triangles)
        for (const glm::vec3& p : {t.v0, t.v1, t.v2}) {
            box.lo = glm::min(box.lo, glm::dvec3(p));
            box.hi = glm::max(box.hi, glm::dvec3(p));
            magnitude = std::max({magnitude, std::abs(double(p.x)), std::abs(double(p.y)), std::abs(double(p.z))});
        }
    for (const RayF64& r : wide)
        magnitude = std::max({magnitude, std::abs(r.origin.x), std::abs(r.origin.y), std::abs(r.origin.z)});
    const double margin = std::max(magnitude * 0x1p-40, 0x1p-900);

    const std::size_t chunks = std::min<std::size_t>(rays.size(), 8 * std::size_t(pool.size()));
    pool.parallelFor(chunks, [&](std::size_t c, unsigned) {
        const std::size_t begin = rays.size() * c / chunks, end = rays.size() * (c + 1) / chunks;
        std::vector<std::uint32_t> octants[8];
        for (std::size_t i = begin; i < end; ++i) {
            const glm::dvec3& d = wide[i].dir;
            octants[(d.x < 0.0) | (d.y < 0.0) << 1 | (d.z < 0.0) << 2].push_back(std::uint32_t(i));
        }
        for (std::vector<std::uint32_t>& ids : octants) ReferenceTraversal(triangles, wide, hits, margin).run(box, std::move(ids));
    });
    return hits;
}

std::vector<ReferenceHit> traceReferenceBrute(const std::vector<Triangle>& triangles, const std::vector<Ray>& rays,
                                              ThreadPool& pool) {
    checkRays(rays);
    std::vector<ReferenceHit> hits(rays.size(), ReferenceHit{kInf, kMissPrim});
    pool.parallelFor(rays.size(), [&](std::size_t i, unsigned) {
        const RayF64 ray = toF64(rays[i]);
        ReferenceHit best{kInf, kMissPrim};
        for (std::uint32_t prim = 0; prim < triangles.size(); ++prim) {
            const Triangle& t = triangles[prim];
            const TriangleHitF64 h = intersectWatertightF64(ray, t.v0, t.v1, t.v2, t.cullBackFace != 0u);
            if (h.hit && h.t > ray.tmin && (h.t < best.t || (h.t == best.t && prim < best.prim)))
                best = ReferenceHit{h.t, prim};
        }
        hits[i] = best;
    });
    return hits;
}

namespace {
constexpr char kCacheMagic[8] = {'D', 'A', 'C', 'R', 'T', 'R', 'F', '1'};
static_assert(std::endian::native == std::endian::little, "the reference cache is written in little-endian order");
}

bool readReferenceCache(const std::string& path, const std::string& key, std::size_t rays, std::size_t triangleCount,
                        std::vector<ReferenceHit>& hits) {
    std::ifstream f(path, std::ios::binary);
    if (!f) return false;
    char magic[8];
    std::uint64_t keySize = 0, count = 0;
    if (!f.read(magic, 8) || std::memcmp(magic, kCacheMagic, 8) != 0 || !f.read(reinterpret_cast<char*>(&keySize), 8) ||
        keySize > 4096)
        throw InputError(path + ": not a dacrt reference cache file; delete it");
    std::string storedKey(keySize, '\0');
    if (!f.read(storedKey.data(), std::streamsize(keySize)) || !f.read(reinterpret_cast<char*>(&count), 8))
        throw InputError(path + ": truncated reference cache file; delete it");
    if (storedKey != key || count != rays) return false;
    hits.resize(rays);
    for (ReferenceHit& h : hits) {
        if (!f.read(reinterpret_cast<char*>(&h.t), 8) || !f.read(reinterpret_cast<char*>(&h.prim), 4))
            throw InputError(path + ": truncated reference cache file; delete it");
        const bool valid = h.prim == kMissPrim ? std::isinf(h.t) && h.t > 0 : h.prim < triangleCount && h.t > 0 && std::isfinite(h.t);
        if (!valid) throw InputError(path + ": damaged reference cache file (a hit that cannot be); delete it");
    }
    if (f.peek() != std::char_traits<char>::eof()) throw InputError(path + ": reference cache file too long; delete it");
    return true;
}

void writeReferenceCache(const std::string& path, const std::string& key, const std::vector<ReferenceHit>& hits) {
    std::filesystem::create_directories(std::filesystem::path(path).parent_path());
    std::string bytes;
    auto append = [&bytes](const void* data, std::size_t size) { bytes.append(static_cast<const char*>(data), size); };
    const std::uint64_t keySize = key.size(), count = hits.size();
    bytes.reserve(32 + key.size() + hits.size() * 12);
    append(kCacheMagic, 8);
    append(&keySize, 8);
    append(key.data(), key.size());
    append(&count, 8);
    for (const ReferenceHit& h : hits) {
        append(&h.t, 8);
        append(&h.prim, 4);
    }
    writeFileAtomically(path, bytes);  // readers never see half a file; concurrent runs do not collide
}

}  // namespace dacrt
