#pragma once
// The public API's tests (tests/library): random scenes and rays as arrays, and hits compared
// bit for bit.
#include <bit>
#include <cmath>
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include <dacrt/dacrt.hpp>

#include "core/random.hpp"

namespace dacrt::test {

// The repository's room, as `dacrt render` renders it by default in the docs.
inline const std::string kRoomScene = std::string(DACRT_TEST_SCENES) + "/../../scenes/room.glb";

// A point light in the middle of the scene, then ambient occlusion with raysPerHit rays per
// hit, a tenth of the scene box's diagonal long.
inline std::vector<FramePass> lightAndOcclusion(const TraceScene& scene, std::uint32_t raysPerHit = 3) {
    const SceneBounds b = scene.bounds();
    FramePass shadow{.name = "shadow: centre", .kind = PassKind::Shadow};
    float diagonal = 0.0f;
    for (int a = 0; a < 3; ++a) {
        shadow.light.position[a] = 0.5f * (b.lo[a] + b.hi[a]);
        diagonal += (b.hi[a] - b.lo[a]) * (b.hi[a] - b.lo[a]);
    }
    FramePass occlusion{.name = "occlusion", .kind = PassKind::Occlusion, .raysPerHit = raysPerHit,
                        .occlusionDistance = 0.1f * std::sqrt(diagonal), .sampleSeed = 1};
    return {shadow, occlusion};
}

struct SceneArrays {
    std::vector<float> positions;
    std::vector<std::uint32_t> indices;
    std::vector<std::uint8_t> singleSided;
};

// `count` triangles of random size and place in [-1, 1]^3, a third of them single-sided.
inline SceneArrays randomSceneArrays(std::uint64_t seed, std::uint32_t count) {
    Random random(seed);
    SceneArrays a;
    for (std::uint32_t k = 0; k < count; ++k) {
        const glm::vec3 centre = random.vec3(-1.0f, 1.0f);
        for (int corner = 0; corner < 3; ++corner) {
            const glm::vec3 p = centre + random.vec3(-0.2f, 0.2f);
            a.positions.insert(a.positions.end(), {p.x, p.y, p.z});
            a.indices.push_back(3 * k + std::uint32_t(corner));
        }
        a.singleSided.push_back(k % 3 == 0);
    }
    return a;
}

// The positions each moved by up to `by` on each axis, as an animation's next frame moves them.
inline std::vector<float> movedPositions(const std::vector<float>& positions, std::uint64_t seed, float by) {
    Random random(seed);
    std::vector<float> moved = positions;
    for (float& c : moved) c += random.uniformFloat(-by, by);
    return moved;
}

// The names of a trace's phases, in the order they ran.
inline std::vector<std::string> phaseNames(const TraceOutput& out) {
    std::vector<std::string> names;
    for (const TraceTimings::Phase& p : out.timings.phases) names.push_back(p.name);
    return names;
}

struct RayArrays {
    std::vector<float> origins;
    std::vector<float> directions;
    std::vector<float> tmax;  // from 0.5 to 4: some segments end before the scene
};

// `count` rays from points around the scene towards points inside it.
inline RayArrays randomRayArrays(std::uint64_t seed, std::uint32_t count) {
    Random random(seed);
    RayArrays a;
    for (std::uint32_t i = 0; i < count; ++i) {
        const glm::vec3 origin = glm::vec3(2.5 * random.onSphere());
        const glm::vec3 direction = random.vec3(-0.8f, 0.8f) - origin;
        a.origins.insert(a.origins.end(), {origin.x, origin.y, origin.z});
        a.directions.insert(a.directions.end(), {direction.x, direction.y, direction.z});
        a.tmax.push_back(random.uniformFloat(0.5f, 4.0f));
    }
    return a;
}

// Equal primitive ids and t, u, v bit for bit; the first difference otherwise.
inline ::testing::AssertionResult sameHits(const std::vector<RayHit>& a, const std::vector<RayHit>& b) {
    if (a.size() != b.size()) return ::testing::AssertionFailure() << a.size() << " hits against " << b.size();
    for (std::size_t i = 0; i < a.size(); ++i) {
        auto bits = [](float f) { return std::bit_cast<std::uint32_t>(f); };
        if (a[i].primitive != b[i].primitive || bits(a[i].t) != bits(b[i].t) || bits(a[i].u) != bits(b[i].u) ||
            bits(a[i].v) != bits(b[i].v))
            return ::testing::AssertionFailure() << "ray " << i << ": primitive " << a[i].primitive << " t " << a[i].t
                                                 << " against primitive " << b[i].primitive << " t " << b[i].t;
    }
    return ::testing::AssertionSuccess();
}

// The same visibility slot by slot: a hit (any primitive) or none, and a ray or none.
inline ::testing::AssertionResult sameVisibility(const std::vector<RayHit>& a, const std::vector<RayHit>& b) {
    if (a.size() != b.size()) return ::testing::AssertionFailure() << a.size() << " slots against " << b.size();
    for (std::size_t i = 0; i < a.size(); ++i)
        if (a[i].hit() != b[i].hit() ||
            (a[i].primitive == kNotTracedPrimitive) != (b[i].primitive == kNotTracedPrimitive))
            return ::testing::AssertionFailure() << "slot " << i << ": primitive " << a[i].primitive << " against "
                                                 << b[i].primitive;
    return ::testing::AssertionSuccess();
}

// Expects `call` to throw InputError whose message contains `part`.
inline void expectInputError(const std::function<void()>& call, const std::string& part) {
    try {
        call();
        ADD_FAILURE() << "no InputError; expected one naming '" << part << "'";
    } catch (const InputError& e) {
        EXPECT_NE(std::string(e.what()).find(part), std::string::npos) << "message: " << e.what();
    }
}

inline std::size_t hitCount(const std::vector<RayHit>& hits) {
    std::size_t n = 0;
    for (const RayHit& h : hits) n += h.hit();
    return n;
}

inline TracerOptions onBackend(Backend backend, unsigned threads = 0) {
    TracerOptions o;
    o.trace.backend = backend;
    o.trace.threads = backend == Backend::CpuSeq ? 0 : threads;
    return o;
}

}  // namespace dacrt::test
