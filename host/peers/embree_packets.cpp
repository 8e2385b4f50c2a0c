#include "peers/embree_packets.hpp"

#include <stdexcept>

namespace dacrt::embree {
namespace {

// Embree's end of a ray's segment: dacrt's whole ray (kNoHitT, finite only so that dacrt's
// arithmetic stays finite) is Embree's unbounded one.
float segmentEnd(const LaneRay& ray) {
    return ray.tmax == kNoHitT ? std::numeric_limits<float>::infinity() : ray.tmax;
}

// dacrt accepts only t > tmin while Embree's tnear is inclusive (t >= tnear). The two differ
// only for a triangle through the point at exactly tmin, which for primary rays (tmin 0)
// means a triangle through the eye, and for secondary rays (tmin 0, origins offset off their
// surface) a triangle through the offset origin; that case is left to Embree rather than
// nudging tnear, which would move every other answer too.
RTCRay embreeRay(const LaneRay& ray) {
    RTCRay r{};
    r.org_x = ray.origin.x;
    r.org_y = ray.origin.y;
    r.org_z = ray.origin.z;
    r.tnear = ray.tmin;
    r.dir_x = ray.dir.x;
    r.dir_y = ray.dir.y;
    r.dir_z = ray.dir.z;
    r.tfar = segmentEnd(ray);
    r.mask = ~0u;
    return r;
}

void setLane(RTCRay16& packet, int lane, const LaneRay& ray) {
    packet.org_x[lane] = ray.origin.x;
    packet.org_y[lane] = ray.origin.y;
    packet.org_z[lane] = ray.origin.z;
    packet.tnear[lane] = ray.tmin;
    packet.dir_x[lane] = ray.dir.x;
    packet.dir_y[lane] = ray.dir.y;
    packet.dir_z[lane] = ray.dir.z;
    packet.time[lane] = 0.0f;
    packet.tfar[lane] = segmentEnd(ray);
    packet.mask[lane] = ~0u;
    packet.id[lane] = unsigned(lane);
    packet.flags[lane] = 0;
}

Hit closestHitOf(const LaneRay& ray, float tfar, unsigned geomID, unsigned primID, float u, float v) {
    if (geomID == RTC_INVALID_GEOMETRY_ID) return Hit{ray.tmax, kMissPrim, 0.0f, 0.0f};
    return Hit{tfar, primID, u, v};  // Embree's u and v weight v1 and v2, as dacrt's do
}

// rtcOccluded marks an occluded ray by setting its tfar to -infinity and keeps nothing of the
// hit; the segment's start is the one depth known to precede it.
Hit occlusionOf(const LaneRay& ray, float tfar) {
    if (tfar == -std::numeric_limits<float>::infinity()) return Hit{ray.tmin, kUnnamedHitPrim, 0.0f, 0.0f};
    return Hit{ray.tmax, kMissPrim, 0.0f, 0.0f};
}

RTCIntersectContext contextOf(bool coherent) {
    RTCIntersectContext context;
    rtcInitIntersectContext(&context);
    if (coherent) context.flags = RTC_INTERSECT_CONTEXT_FLAG_COHERENT;
    return context;
}

}  // namespace

void intersect16(RTCScene scene, const Packet16& packet, bool coherent, Hit (&hits)[16]) {
    RTCIntersectContext context = contextOf(coherent);
    alignas(64) RTCRayHit16 q;
    for (int l = 0; l < 16; ++l) {
        setLane(q.ray, l, packet.rays[l]);
        q.hit.geomID[l] = RTC_INVALID_GEOMETRY_ID;
        q.hit.primID[l] = RTC_INVALID_GEOMETRY_ID;
        q.hit.instID[0][l] = RTC_INVALID_GEOMETRY_ID;
    }
    rtcIntersect16(packet.valid, scene, &context, &q);
    for (int l = 0; l < 16; ++l)
        if (packet.valid[l])
            hits[l] = closestHitOf(packet.rays[l], q.ray.tfar[l], q.hit.geomID[l], q.hit.primID[l], q.hit.u[l], q.hit.v[l]);
}

void occluded16(RTCScene scene, const Packet16& packet, bool coherent, Hit (&hits)[16]) {
    RTCIntersectContext context = contextOf(coherent);
    alignas(64) RTCRay16 q;
    for (int l = 0; l < 16; ++l) setLane(q, l, packet.rays[l]);
    rtcOccluded16(packet.valid, scene, &context, &q);
    for (int l = 0; l < 16; ++l)
        if (packet.valid[l]) hits[l] = occlusionOf(packet.rays[l], q.tfar[l]);
}

Hit intersect1(RTCScene scene, const LaneRay& ray) {
    RTCIntersectContext context = contextOf(false);
    RTCRayHit closest{};
    closest.ray = embreeRay(ray);
    closest.hit.geomID = RTC_INVALID_GEOMETRY_ID;
    closest.hit.primID = RTC_INVALID_GEOMETRY_ID;
    closest.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
    rtcIntersect1(scene, &context, &closest);
    return closestHitOf(ray, closest.ray.tfar, closest.hit.geomID, closest.hit.primID, closest.hit.u, closest.hit.v);
}

Hit occluded1(RTCScene scene, const LaneRay& ray) {
    RTCIntersectContext context = contextOf(false);
    RTCRay occlusion = embreeRay(ray);
    rtcOccluded1(scene, &context, &occlusion);
    return occlusionOf(ray, occlusion.tfar);
}

void FirstFailure::keep(std::exception_ptr failure) {
    std::lock_guard<std::mutex> lock(mutex_);
    if (!first_) first_ = failure;
}

void FirstFailure::keepError(const std::string& error) {
    if (!error.empty()) keep(std::make_exception_ptr(std::runtime_error(error)));
}

void FirstFailure::rethrow() const {
    if (first_) std::rethrow_exception(first_);
}

}  // namespace dacrt::embree
