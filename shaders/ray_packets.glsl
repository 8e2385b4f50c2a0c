// Ray packets of the DACRT kernel (kPacketFlush; Mora 2011's packets in the form that keeps the
// result exact, as the cpu backend's): primary rays filtered one 8x8 pixel tile at a time high
// in the tree, where a packet test stands for some 64 ray tests, and one by one below.
#ifndef DACRT_RAY_PACKETS_GLSL
#define DACRT_RAY_PACKETS_GLSL

// False only where rayMayCrossCell(ray, lo, hi, tmax) is false for every ray of the packet
// (rays that share their start, gRayOrigin and gRayTmin): each ray's slab values
// (lo - origin) * invDir lie between the packet's corner products with the same first factor,
// rounding being monotone (PacketBounds in layout.h), so the packet's interval holds each ray's.
bool packetMayCrossCell(PacketBounds p, vec3 lo, vec3 hi) {
    float tNear = -kNoHitT, tFar = kNoHitT;
    [[unroll]] for (int a = 0; a < 3; ++a) {
        if (((p.unboundedAxes >> uint(a)) & 1u) != 0u) continue;
        precise float d0 = lo[a] - gRayOrigin[a];
        precise float d1 = hi[a] - gRayOrigin[a];
        precise float q0 = d0 * p.invLo[a];
        precise float q1 = d0 * p.invHi[a];
        precise float q2 = d1 * p.invLo[a];
        precise float q3 = d1 * p.invHi[a];
        tNear = max(tNear, min(min(q0, q1), min(q2, q3)));
        tFar = min(tFar, max(max(q0, q1), max(q2, q3)));
    }
    return tNear <= tFar && tFar >= gRayTmin;
}

// Whether the ray has its final hit (a leaf of a packet flush ended it).
bool rayDone(uint id) { return RAY_IDS(gDoneFlagsAt + id) != 0u; }

#endif
