// Host side of the parallel scheme: axis choice, binning, the transfer schedule.
#include <set>

#include <gtest/gtest.h>

#include "core/procedural.hpp"
#include "cpu/predicates.hpp"
#include "cpu/scene_division.hpp"
#include "support/frames.hpp"

using namespace dacrt;
using namespace dacrt::test;

namespace {

Scene wideRow() {  // spheres in a row along x: wide in x, shallow in z
    std::vector<Mesh> meshes;
    for (int i = 0; i < 6; ++i) meshes.push_back(icosphere({float(i) * 1.5f, 0.0f, 0.0f}, 0.6f, 2));
    return sceneFromMeshes(meshes);
}

}  // namespace

TEST(DivisionAxis, NeverTheAxisPointingAtTheCamera) {
    const Scene s = wideRow();
    for (const auto& [eye, forbidden] : {std::pair{glm::dvec3(3.75, 0.0, 20.0), 2}, std::pair{glm::dvec3(-20.0, 0.1, 0.2), 0},
                                         std::pair{glm::dvec3(3.7, 25.0, 0.1), 1}}) {
        CameraOptions o;
        o.eye = eye;
        o.target = glm::dvec3(3.75, 0.0, 0.0);
        o.up = glm::dvec3(0.0, 0.0, 1.0);
        if (forbidden != 1) o.up = glm::dvec3(0.0, 1.0, 0.0);
        const Frame frame(wideRow(), defaultCamera(s, 64, 48, o), 64, 48);
        EXPECT_NE(chooseDivisionAxis(frame.geometry, 4), forbidden);
    }
    CameraOptions front;
    front.eye = glm::dvec3(3.75, 0.0, 20.0);
    const Frame frame(wideRow(), defaultCamera(s, 64, 48, front), 64, 48);
    EXPECT_EQ(chooseDivisionAxis(frame.geometry, 4), 0) << "a row along x seen from the front divides along x";
}

TEST(Division, BinsEveryRayThatCanHitAndEveryOverlappingTriangle) {
    const Scene s = wideRow();
    const Frame frame(wideRow(), defaultCamera(s, 80, 60), 80, 60);
    ThreadPool pool(2);
    for (unsigned n : {1u, 3u, 7u}) {
        MemoryPlan plan;
        const Division d = divideScene(frame.geometry, n, 0, pool, plan);
        ASSERT_TRUE(d.complete);
        ASSERT_EQ(d.regions.size(), n);
        EXPECT_EQ(d.regions.front().lo, frame.geometry.sceneBox.lo);
        EXPECT_EQ(d.regions.back().hi, frame.geometry.sceneBox.hi);
        std::vector<int> seen(frame.rays.size(), 0);
        for (unsigned k = 0; k < n; ++k) {
            const Region& r = d.regions[k];
            if (k > 0) {
                EXPECT_EQ(r.lo.x, d.regions[k - 1].hi.x);
            }
            for (std::uint32_t i = r.rayBegin; i < r.rayEnd; ++i) ++seen[d.rayIds[i]];
            std::set<std::uint32_t> tris(d.triIds.begin() + r.triBegin, d.triIds.begin() + r.triEnd);
            EXPECT_EQ(tris.size(), r.triEnd - r.triBegin) << "a triangle twice in one region";
            const glm::vec3 lo = r.lo - glm::vec3(frame.geometry.margin), hi = r.hi + glm::vec3(frame.geometry.margin);
            for (std::uint32_t t = 0; t < frame.bounds.size(); ++t) {
                const bool overlaps = shared::boundsOverlap(frame.bounds[t].lo, frame.bounds[t].hi, lo, hi);
                EXPECT_EQ(overlaps, tris.count(t) == 1) << "triangle " << t << " region " << k;
            }
        }
        const std::vector<Hit> brute = frame.trace(Backend::Brute, 0, 2).hits;
        for (std::size_t i = 0; i < seen.size(); ++i) {
            EXPECT_LE(seen[i], 1) << "ray " << i << " binned twice";
            if (brute[i].prim != kMissPrim) {
                EXPECT_EQ(seen[i], 1) << "ray " << i << " hits but was culled";
            }
        }
        EXPECT_EQ(d.culledRays + d.rayIds.size(), frame.rays.size());
        EXPECT_EQ(d.triIds.size(), frame.bounds.size() + d.straddlerCopies);
        std::uint64_t planned = 0;
        for (const auto& [name, bytes] : plan.buffers)
            if (name.rfind("triangle ids", 0) == 0) planned = bytes;
        EXPECT_EQ(planned, d.triIds.size() * 4) << "the plan counts every straddler copy";
    }
}

TEST(TransferSchedule, RoundsUseDistinctRangesAndFollowTheRays) {
    const Scene s = wideRow();
    const Frame frame(wideRow(), defaultCamera(s, 80, 60), 80, 60);  // camera above the middle in x
    ThreadPool pool(1);
    MemoryPlan plan;
    const Division d = divideScene(frame.geometry, 6, 0, pool, plan);
    const std::vector<TransferRound> rounds = transferSchedule(d);
    ASSERT_FALSE(rounds.empty());
    bool low = false, high = false;
    for (const TransferRound& round : rounds) {
        std::set<std::uint32_t> rayRegions, triRegions;
        for (const TransferPair& p : round.pairs) {
            EXPECT_TRUE(rayRegions.insert(p.rayRegion).second) << round.name;
            EXPECT_TRUE(triRegions.insert(p.triRegion).second) << round.name;
            const bool towardLow = p.triRegion < p.rayRegion;
            EXPECT_TRUE(towardLow ? d.raysTowardLow[p.rayRegion] : d.raysTowardHigh[p.rayRegion]) << round.name;
            (towardLow ? low : high) = true;
        }
    }
    EXPECT_TRUE(low && high) << "a centred camera sends rays both ways";

    // A camera beyond the high end of the axis only sends rays toward lower regions.
    CameraOptions side;
    side.eye = glm::dvec3(30.0, 0.5, 3.0);
    side.target = glm::dvec3(3.75, 0.0, 0.0);
    const Frame sideFrame(wideRow(), defaultCamera(s, 80, 60, side), 80, 60);
    MemoryPlan plan2;
    const Division d2 = divideScene(sideFrame.geometry, 6, 0, pool, plan2);
    for (const TransferRound& round : transferSchedule(d2))
        for (const TransferPair& p : round.pairs) EXPECT_LT(p.triRegion, p.rayRegion) << round.name;
}
