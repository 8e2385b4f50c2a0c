// Compiled once per instruction set by Highway's foreach_target (this file includes itself);
// HWY_DYNAMIC_DISPATCH picks the best one the machine supports on first use.
#undef HWY_TARGET_INCLUDE
#define HWY_TARGET_INCLUDE "core/triangle_bounds_lanes.cpp"
#include <hwy/foreach_target.h>  // must come before highway.h
#include <hwy/highway.h>

#include "core/triangle_bounds_lanes.hpp"

HWY_BEFORE_NAMESPACE();
namespace dacrt::bounds_lanes {
namespace HWY_NAMESPACE {
namespace hn = hwy::HWY_NAMESPACE;

// A vertex's x, y, z and the word after it (cullBackFace or padding) in one vector: lane 3 is
// computed with the others and dropped (zeroed in the bounds, as Bounds{} leaves the padding).
void TriangleBounds(const Triangle* triangles, std::size_t count, Bounds* bounds, float* boxLo, float* boxHi) {
#if HWY_TARGET == HWY_SCALAR  // one lane: the scalar loop itself
    Box box;
    box.lo = glm::vec3(boxLo[0], boxLo[1], boxLo[2]);
    box.hi = glm::vec3(boxHi[0], boxHi[1], boxHi[2]);
    for (std::size_t i = 0; i < count; ++i) {
        bounds[i] = triangleBounds(triangles[i]);
        box.extend(triangles[i].v0);
        box.extend(triangles[i].v1);
        box.extend(triangles[i].v2);
    }
    for (int a = 0; a < 3; ++a) boxLo[a] = box.lo[a], boxHi[a] = box.hi[a];
#else
    const hn::FixedTag<float, 4> d;
    const auto xyz = hn::FirstN(d, 3);
    auto lo = hn::LoadU(d, boxLo), hi = hn::LoadU(d, boxHi);
    for (std::size_t i = 0; i < count; ++i) {
        const float* t = reinterpret_cast<const float*>(triangles + i);
        const auto v0 = hn::LoadU(d, t), v1 = hn::LoadU(d, t + 4), v2 = hn::LoadU(d, t + 8);
        // glm::min(x, y) is (y < x) ? y : x and glm::max(x, y) is (x < y) ? y : x, lane by lane.
        const auto min12 = hn::IfThenElse(hn::Lt(v2, v1), v2, v1);
        const auto max12 = hn::IfThenElse(hn::Lt(v1, v2), v2, v1);
        const auto triLo = hn::IfThenElse(hn::Lt(min12, v0), min12, v0);
        const auto triHi = hn::IfThenElse(hn::Lt(v0, max12), max12, v0);
        float* b = reinterpret_cast<float*>(bounds + i);
        hn::StoreU(hn::IfThenElseZero(xyz, triLo), d, b);
        hn::StoreU(hn::IfThenElseZero(xyz, triHi), d, b + 4);
        // Box::extend(v0), (v1), (v2): lo = glm::min(lo, p), hi = glm::max(hi, p).
        lo = hn::IfThenElse(hn::Lt(v0, lo), v0, lo);
        hi = hn::IfThenElse(hn::Lt(hi, v0), v0, hi);
        lo = hn::IfThenElse(hn::Lt(v1, lo), v1, lo);
        hi = hn::IfThenElse(hn::Lt(hi, v1), v1, hi);
        lo = hn::IfThenElse(hn::Lt(v2, lo), v2, lo);
        hi = hn::IfThenElse(hn::Lt(hi, v2), v2, hi);
    }
    hn::StoreU(lo, d, boxLo);
    hn::StoreU(hi, d, boxHi);
#endif
}

}  // namespace HWY_NAMESPACE
}  // namespace dacrt::bounds_lanes
HWY_AFTER_NAMESPACE();

#if HWY_ONCE
namespace dacrt {
namespace bounds_lanes {
HWY_EXPORT(TriangleBounds);
}  // namespace bounds_lanes

void triangleBoundsLanes(const Triangle* triangles, std::size_t count, Bounds* bounds, Box& box) {
    float lo[4] = {box.lo.x, box.lo.y, box.lo.z, 0.0f}, hi[4] = {box.hi.x, box.hi.y, box.hi.z, 0.0f};
    HWY_DYNAMIC_DISPATCH(bounds_lanes::TriangleBounds)(triangles, count, bounds, lo, hi);
    box.lo = glm::vec3(lo[0], lo[1], lo[2]);
    box.hi = glm::vec3(hi[0], hi[1], hi[2]);
}

static_assert(sizeof(Triangle) == 48 && offsetof(Triangle, v1) == 16 && offsetof(Triangle, v2) == 32,
              "a triangle is three 16-byte vertex slots");
static_assert(sizeof(Bounds) == 32 && offsetof(Bounds, hi) == 16, "bounds are two 16-byte slots");

}  // namespace dacrt
#endif
