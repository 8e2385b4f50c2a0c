// The SIMD kernels against the scalar predicates they replace, on every instruction set this
// binary holds that the machine runs: same ids in the same order, same hits bit for bit.
#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <cstring>
#include <functional>
#include <limits>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "core/camera.hpp"
#include "core/random.hpp"
#include "cpu/cull_lanes.hpp"
#include "cpu/frame_geometry.hpp"
#include "cpu/predicates.hpp"
#include "cpu/ray_packet.hpp"
#include "cpu/simd_kernels.hpp"
#include "support/simd_targets.hpp"
#include "cpu/traversal.hpp"
#include "cpu/triangle_skips.hpp"

using namespace dacrt;

namespace {

using EveryTarget = test::OnEveryTarget;

// Coordinates drawn from a few values on purpose: equal coordinates (a ray origin on a cell
// face, bounds touching a cell) and zero direction components are where a kernel that
// differs from the scalar rule would show.
float adversarialCoordinate(Random& rng) {
    static const float kValues[] = {-1.0f, -0.5f, 0.0f, -0.0f, 0.25f, 0.5f, 1.0f, 1e-30f, 3.0f};
    if (rng.uniform() < 0.4) return kValues[rng.index(std::size(kValues))];
    return rng.uniformFloat(-2.0f, 2.0f) * (rng.uniform() < 0.2 ? 1e6f : 1.0f);
}

// parallelChance: of each component of the direction being 0 (the ray parallel to a slab).
Ray randomRay(Random& rng, double parallelChance = 0.15) {
    glm::vec3 origin{adversarialCoordinate(rng), adversarialCoordinate(rng), adversarialCoordinate(rng)};
    glm::dvec3 dir = rng.onSphere();
    for (int a = 0; a < 3; ++a)
        if (rng.uniform() < parallelChance) dir[a] = 0.0;
    if (dir == glm::dvec3(0.0)) dir.z = 1.0;
    return makeRay(origin, dir, rng.uniform() < 0.3 ? rng.uniformFloat(0.0f, 1.0f) : 0.0f);
}

Box randomCell(Random& rng) {
    Box b;
    for (int a = 0; a < 3; ++a) {
        float p = adversarialCoordinate(rng), q = rng.uniform() < 0.1 ? p : adversarialCoordinate(rng);
        b.lo[a] = std::min(p, q);
        b.hi[a] = std::max(p, q);
    }
    return b;
}

std::vector<std::uint32_t> scalarPartition(std::vector<std::uint32_t> ids, std::uint32_t& kept,
                                           const std::function<bool(std::uint32_t)>& passes) {
    std::vector<std::uint32_t> out, rest;
    for (std::uint32_t id : ids) (passes(id) ? out : rest).push_back(id);
    kept = std::uint32_t(out.size());
    out.insert(out.end(), rest.begin(), rest.end());
    return out;
}

std::vector<std::uint32_t> shuffledIds(Random& rng, std::uint32_t universe, std::uint32_t count) {
    std::vector<std::uint32_t> ids(universe);
    for (std::uint32_t i = 0; i < universe; ++i) ids[i] = i;
    rng.shuffle(ids);
    ids.resize(count);
    return ids;
}

// A kernel's partition against the scalar one (same ids, same order), tallying both answers
// so that a test can require both to be common.
struct PartitionTally {
    std::uint32_t kept = 0, rejected = 0;
    ::testing::AssertionResult check(std::uint32_t kept_, std::uint32_t expectedKept, const std::vector<std::uint32_t>& ids,
                                     const std::vector<std::uint32_t>& expected) {
        if (kept_ != expectedKept || ids != expected)
            return ::testing::AssertionFailure() << "kept " << kept_ << " ids against the scalar " << expectedKept;
        kept += kept_;
        rejected += std::uint32_t(ids.size()) - kept_;
        return ::testing::AssertionSuccess();
    }
};

bool sameHit(const Hit& a, const Hit& b) { return std::memcmp(&a, &b, sizeof(Hit)) == 0; }

}  // namespace

// With their own starts, sharing one, sharing a segment with no hit yet (the broadcast
// paths), and each with a segment of its own and no hit yet (the hits not read); with rays
// parallel to slabs in most vectors, and in none (the kernels' short slabs).
TEST_F(EveryTarget, RayPartitionKeepsTheScalarAnswerAndOrder) {
    forEachTarget([] {
      for (const double parallelChance : {0.15, 0.0})
      for (const simd::SharedRayFields shared :
           {simd::SharedRayFields::None, simd::SharedRayFields::Start, simd::SharedRayFields::Segment,
            simd::SharedRayFields::OwnSegment}) {
        const bool shareStart = shared == simd::SharedRayFields::Start;
        const bool shareSegment = shared == simd::SharedRayFields::Segment;
        const bool ownSegment = shared == simd::SharedRayFields::OwnSegment;
        SCOPED_TRACE(shareStart     ? "rays share their start"
                     : shareSegment ? "rays share their segment"
                     : ownSegment   ? "rays each of its own segment"
                                    : "rays start apart");
        SCOPED_TRACE(parallelChance > 0.0 ? "some rays parallel to slabs" : "no ray parallel to a slab");
        Random rng(11);
        PartitionTally tally;
        std::vector<Ray> rays(300);
        std::vector<Hit> hits(rays.size(), missHit());
        for (std::size_t i = 0; i < rays.size(); ++i) {
            rays[i] = randomRay(rng, parallelChance);
            if (shareStart && i > 0) {
                rays[i].origin = rays[0].origin;
                rays[i].tmin = rays[0].tmin;
            }
            if (shareSegment) {  // live any-hit rays: the same segment, each with its miss hit
                if (i == 0) rays[0].tmax = rng.uniformFloat(0.1f, 4.0f);  // so that the segment's end decides some
                if (i > 0) {
                    rays[i].tmin = rays[0].tmin;
                    rays[i].tmax = rays[0].tmax;
                }
                hits[i] = missHit(rays[i]);
            } else if (ownSegment) {  // live any-hit rays (a frame's passes together): each its own end
                rays[i].tmax = rng.uniform() < 0.2 ? kNoHitT : rng.uniformFloat(0.1f, 4.0f);
                hits[i] = missHit(rays[i]);
            } else if (rng.uniform() < 0.5) {
                hits[i] = Hit{rng.uniform() < 0.2 ? 0.0f : rng.uniformFloat(0.0f, 4.0f), 1, 0, 0};
            }
        }
        for (int trial = 0; trial < 400; ++trial) {
            const Box cell = randomCell(rng);
            const std::uint32_t count = std::uint32_t(rng.index(70));  // every tail length of every width
            std::vector<std::uint32_t> ids = shuffledIds(rng, std::uint32_t(rays.size()), count);
            std::uint32_t expectedKept = 0;
            const std::vector<std::uint32_t> expected = scalarPartition(ids, expectedKept, [&](std::uint32_t id) {
                return shared::rayMayCrossCell(rays[id], cell.lo, cell.hi, hits[id].t);
            });
            std::vector<std::uint32_t> scratch(count + simd::kScratchSlack);
            // OwnSegment reads no hit record: records that disagree with the rays must not matter.
            std::vector<Hit> given = hits;
            if (ownSegment)
                for (Hit& h : given) h.t = 0.0f;
            const std::uint32_t kept = simd::partitionRaysMayCrossCell(rays.data(), given.data(), ids.data(), count, cell,
                                                                       shared, scratch.data());
            ASSERT_TRUE(tally.check(kept, expectedKept, ids, expected)) << "trial " << trial;
        }
        EXPECT_GT(tally.kept, 400u);  // both answers are common, so both are compared
        EXPECT_GT(tally.rejected, 1000u);
      }
    });
}

// The end of a leaf: the rays whose hits end them, moved by the scalar loop's swaps (the same
// ids in the same order, not only the same set), for closest and any hits, with hits on the
// box's far faces (where the widened exit decides) and no hits among them.
TEST_F(EveryTarget, LeafEndMovesTheRaysTheScalarLoopMoves) {
    forEachTarget([] {
        Random rng(31);
        std::uint32_t moved = 0, stayed = 0, decidedByTheExit = 0;
        for (int trial = 0; trial < 600; ++trial) {
            const Box box = randomCell(rng);
            const bool anyHit = rng.uniform() < 0.2;
            std::vector<Ray> rays(100);
            std::vector<Hit> hits(rays.size(), missHit());
            for (std::size_t i = 0; i < rays.size(); ++i) {
                rays[i] = randomRay(rng);
                if (rng.uniform() < 0.2) continue;  // no hit
                const shared::RayInterval r = shared::rayBoxInterval(rays[i], box.lo, box.hi);
                // Near the widened exit on either side, else anywhere on the ray.
                const float exit = r.tFar;
                const double pick = rng.uniform();
                float t = pick < 0.3   ? exit
                          : pick < 0.5 ? std::nextafter(exit, kNoHitT)
                          : pick < 0.6 ? std::nextafter(exit, -kNoHitT)
                                       : rng.uniformFloat(0.0f, 4.0f);
                if (!std::isfinite(t)) t = rng.uniformFloat(0.0f, 4.0f);
                hits[i] = Hit{t, std::uint32_t(rng.index(50)), 0.25f, 0.5f};
            }
            const std::uint32_t count = std::uint32_t(rng.index(70));
            std::vector<std::uint32_t> ids = shuffledIds(rng, std::uint32_t(rays.size()), count), expected = ids;
            std::uint32_t expectedEnded = 0;
            for (std::uint32_t k = 0; k < count; ++k) {  // DacrtTraversal::endRaysHitInBox's scalar loop
                const std::uint32_t id = expected[k];
                const bool hitAtAll = hits[id].prim != kMissPrim;
                const bool endsInBox = shared::hitEndsInBox(rays[id], box.lo, box.hi, hits[id].t);
                if (hitAtAll && !anyHit && endsInBox != (hits[id].t <= shared::rayBoxIntervalRounded(rays[id], box.lo, box.hi).tFar))
                    ++decidedByTheExit;
                if (hitAtAll && (anyHit || endsInBox)) std::swap(expected[k], expected[expectedEnded++]);
            }
            const std::uint32_t ended = simd::endRaysHitInBox(rays.data(), hits.data(), ids.data(), count, box, anyHit);
            ASSERT_EQ(ended, expectedEnded) << "trial " << trial;
            ASSERT_EQ(ids, expected) << "trial " << trial;
            moved += ended;
            stayed += count - ended;
        }
        EXPECT_GT(moved, 2000u);  // both answers are common, so both are compared
        EXPECT_GT(stayed, 2000u);
        EXPECT_GT(decidedByTheExit, 20u) << "hits just past the rounded exit must be among them";
    });
}

// Children of a cell the triangles overlap: the one-face test answers boundsOverlap, from the
// records and from the same bounds in columns alike.
TEST_F(EveryTarget, FacePartitionAnswersTheFullOverlapTestForAChildCellAndItsComplement) {
    forEachTarget([] {
        Random rng(14);
        PartitionTally tally;
        for (int trial = 0; trial < 300; ++trial) {
            const Box parent = randomCell(rng);
            std::vector<Bounds> bounds(200);
            for (Bounds& b : bounds)
                for (int a = 0; a < 3; ++a) {  // lo <= parent.hi and hi >= parent.lo: they overlap it
                    b.lo[a] = std::min(adversarialCoordinate(rng), parent.hi[a]);
                    b.hi[a] = std::max({b.lo[a], parent.lo[a], adversarialCoordinate(rng)});
                }
            const int axis = int(rng.index(3));
            const bool lowSide = rng.uniform() < 0.5;
            Box child = parent;
            const float face = rng.uniform() < 0.3 ? bounds[rng.index(bounds.size())].lo[axis]
                                                    : rng.uniformFloat(parent.lo[axis], parent.hi[axis]);
            (lowSide ? child.hi : child.lo)[axis] = face;
            const std::uint32_t count = std::uint32_t(rng.index(70));
            std::vector<std::uint32_t> ids = shuffledIds(rng, std::uint32_t(bounds.size()), count);
            for (const Bounds& b : bounds) ASSERT_TRUE(shared::boundsOverlap(b.lo, b.hi, parent.lo, parent.hi));
            // Beyond: the complement, as a second child filters its sibling's triangles.
            const simd::FaceSide side = rng.uniform() < 0.5 ? simd::FaceSide::Reaching : simd::FaceSide::Beyond;
            std::uint32_t expectedKept = 0;
            const std::vector<std::uint32_t> expected = scalarPartition(ids, expectedKept, [&](std::uint32_t id) {
                return shared::boundsOverlap(bounds[id].lo, bounds[id].hi, child.lo, child.hi) ==
                       (side == simd::FaceSide::Reaching);
            });
            std::vector<std::uint32_t> scratch(count + simd::kScratchSlack);
            // The same bounds in columns (FrameGeometry::boundsColumns) answer the same.
            std::vector<float> columns(6 * bounds.size());
            for (std::size_t i = 0; i < bounds.size(); ++i)
                for (int a = 0; a < 3; ++a) {
                    columns[std::size_t(a) * bounds.size() + i] = bounds[i].lo[a];
                    columns[std::size_t(3 + a) * bounds.size() + i] = bounds[i].hi[a];
                }
            std::vector<std::uint32_t> columnIds = ids;
            const std::uint32_t kept =
                simd::partitionTrianglesOnFace(bounds.data(), ids.data(), count, axis, lowSide, face, scratch.data(), side);
            ASSERT_TRUE(tally.check(kept, expectedKept, ids, expected)) << "trial " << trial;
            const simd::TriangleFaces faces{bounds.data(), columns.data(), bounds.size()};
            const std::uint32_t keptFromColumns =
                simd::partitionTrianglesOnFace(faces, columnIds.data(), count, axis, lowSide, face, scratch.data(), side);
            ASSERT_EQ(keptFromColumns, kept) << "trial " << trial;
            ASSERT_EQ(columnIds, ids) << "trial " << trial;
        }
        EXPECT_GT(tally.kept, 1000u);
        EXPECT_GT(tally.rejected, 1000u);
    });
}

// The box of a node's triangles (DacrtTraversal::tightenedBox): the smallest lo and largest hi
// of the bounds of any subset of ids, in any order, with counts that leave a vector's tail
// and none at all (an empty box); the equal and signed-zero coordinates of
// adversarialCoordinate included (a zero's sign may differ, which no comparison sees).
TEST_F(EveryTarget, TriangleBoundsBoxIsTheScalarMinimumAndMaximum) {
    forEachTarget([] {
        Random rng(15);
        for (int trial = 0; trial < 500; ++trial) {
            std::vector<Bounds> bounds(150);
            for (Bounds& b : bounds)
                for (int a = 0; a < 3; ++a) {
                    const float p = adversarialCoordinate(rng), q = adversarialCoordinate(rng);
                    b.lo[a] = std::min(p, q);
                    b.hi[a] = std::max(p, q);
                }
            const std::uint32_t count = std::uint32_t(rng.index(70));
            const std::vector<std::uint32_t> ids = shuffledIds(rng, std::uint32_t(bounds.size()), count);
            Box expected;
            for (std::uint32_t id : ids) {
                expected.lo = glm::min(expected.lo, bounds[id].lo);
                expected.hi = glm::max(expected.hi, bounds[id].hi);
            }
            const Box got = simd::boundsOfTriangles(bounds.data(), ids.data(), count);
            for (int a = 0; a < 3; ++a) {
                ASSERT_EQ(got.lo[a], expected.lo[a]) << "trial " << trial << " axis " << a << " of " << count;
                ASSERT_EQ(got.hi[a], expected.hi[a]) << "trial " << trial << " axis " << a << " of " << count;
            }
            ASSERT_EQ(got.empty(), count == 0) << "trial " << trial;
        }
    });
}

// The division's ray binning: slabs as the division makes them (equal widths, widened boxes),
// rays starting inside, outside and on the slabs' faces, parallel to the axis or not, counts
// that leave a vector's tail. Every region tested in lanes answers as the walk region by
// region; past the last ray nothing is written. (33 and more regions go ray by ray: those
// trials check that the fallback is taken and answers.)
TEST_F(EveryTarget, RayBinningFindsTheWalksFirstRegion) {
    forEachTarget([] {
        Random rng(15);
        std::uint32_t binned = 0, none = 0, pastTheFirstRegion = 0, alongNoAxisBinned = 0;
        for (int trial = 0; trial < 300; ++trial) {
            const Box box = randomCell(rng);
            const int axis = int(rng.index(3));
            const std::uint32_t count = trial % 50 == 0 ? 33 + std::uint32_t(rng.index(8))
                                                        : 1 + std::uint32_t(rng.index(simd::kMostRegionsInLanes));
            const float margin = rng.uniform() < 0.5 ? 0.0f : 1e-3f;
            std::vector<float> boundary(count + 1);
            for (std::uint32_t k = 0; k <= count; ++k)
                boundary[k] = float(double(box.lo[axis]) + (double(box.hi[axis]) - double(box.lo[axis])) * k / count);
            boundary[0] = box.lo[axis];
            boundary[count] = box.hi[axis];
            std::vector<glm::vec3> wideLo(count), wideHi(count);
            for (std::uint32_t k = 0; k < count; ++k) {
                wideLo[k] = box.lo - glm::vec3(margin);
                wideHi[k] = box.hi + glm::vec3(margin);
                wideLo[k][axis] = boundary[k] - margin;
                wideHi[k][axis] = boundary[k + 1] + margin;
            }
            const simd::RegionSlabs slabs{.axis = axis,
                                          .count = count,
                                          .boundary = boundary.data(),
                                          .wideLo = wideLo.data(),
                                          .wideHi = wideHi.data(),
                                          .sceneLo = box.lo - glm::vec3(margin),
                                          .sceneHi = box.hi + glm::vec3(margin)};
            std::vector<Ray> rays(1 + rng.index(70));
            for (Ray& r : rays) {
                r = randomRay(rng);
                if (rng.uniform() < 0.3) r.origin[axis] = boundary[rng.index(count + 1)];  // on a face
            }
            constexpr std::uint32_t kUnwritten = 0xDEADBEEFu;
            constexpr std::size_t kGuard = 16;
            std::vector<std::uint32_t> region(rays.size() + kGuard, kUnwritten);
            simd::firstRegionsOfRays(rays.data(), rays.size(), slabs, region.data());
            for (std::size_t i = 0; i < rays.size(); ++i) {
                const std::uint32_t expected = simd::firstRegionOfRay(rays[i], slabs);
                ASSERT_EQ(region[i], expected) << "trial " << trial << ", ray " << i << " of " << rays.size();
                ++(expected == simd::kNoRegion ? none : binned);
                pastTheFirstRegion += expected != simd::kNoRegion && expected > 0;
                alongNoAxisBinned += expected != simd::kNoRegion && rays[i].dir[axis] == 0.0f;
            }
            for (std::size_t i = rays.size(); i < region.size(); ++i) ASSERT_EQ(region[i], kUnwritten) << "trial " << trial;
        }
        EXPECT_GT(binned, 1000u);
        EXPECT_GT(none, 1000u);
        EXPECT_GT(pastTheFirstRegion, 300u);
        EXPECT_GT(alongNoAxisBinned, 50u);
    });
}

// The leaf's structure-of-arrays copy: each lane the bits of its triangle's fields (NaN
// payloads, negative zeros and the face flag included), the lanes past the count the first
// triangle's, for every count up to a full batch and ids in any order.
TEST_F(EveryTarget, LeafGatherCopiesEveryFieldBitForBit) {
    forEachTarget([] {
        Random rng(17);
        std::vector<Triangle> tris(300);
        const float odd[] = {-0.0f, std::numeric_limits<float>::quiet_NaN(), -std::numeric_limits<float>::infinity(),
                             std::numeric_limits<float>::denorm_min()};
        for (Triangle& t : tris) {
            for (glm::vec3* v : {&t.v0, &t.v1, &t.v2})
                for (int c = 0; c < 3; ++c) (*v)[c] = rng.uniform() < 0.05 ? odd[rng.index(4)] : rng.uniformFloat(-9.0f, 9.0f);
            t.cullBackFace = std::uint32_t(rng.index(2));
        }
        for (std::uint32_t count = 1; count <= simd::kLeafBatch; ++count) {
            const std::vector<std::uint32_t> ids = shuffledIds(rng, std::uint32_t(tris.size()), count);
            simd::LeafTriangles batch;
            constexpr std::uint32_t kUnwritten = 0xDEADBEEFu;  // a lane past the target's last vector
            std::fill(std::begin(batch.prim), std::end(batch.prim), kUnwritten);
            simd::gatherLeafTriangles(tris.data(), ids.data(), count, batch);
            ASSERT_EQ(batch.count, count);
            for (std::size_t j = 0; j < simd::kLeafBatch; ++j) {
                if (j >= count && batch.prim[j] == kUnwritten) break;
                const std::uint32_t id = ids[j < count ? j : 0];
                const Triangle& t = tris[id];
                const glm::vec3* v[3] = {&t.v0, &t.v1, &t.v2};
                ASSERT_EQ(batch.prim[j], id) << "count " << count << " lane " << j;
                ASSERT_EQ(batch.cullBackFace[j], t.cullBackFace) << "count " << count << " lane " << j;
                for (int k = 0; k < 3; ++k)
                    for (int c = 0; c < 3; ++c)
                        ASSERT_EQ(std::bit_cast<std::uint32_t>(batch.vertex[k][c][j]), std::bit_cast<std::uint32_t>((*v[k])[c]))
                            << "count " << count << " lane " << j << " vertex " << k << " coordinate " << c;
            }
        }
    });
}

// Rays aimed at vertices and edges shared by neighbouring triangles, duplicated triangles
// (equal t: the tie rule decides), degenerate ones, far offsets and grazing directions.
TEST_F(EveryTarget, LeafBatchGivesTheScalarHitsBitForBit) {
    forEachTarget([] {
        Random rng(13);
        std::size_t hitsFound = 0, tiesOnDuplicates = 0;
        for (int trial = 0; trial < 300; ++trial) {
            const float scale = rng.uniform() < 0.3 ? 1e5f : 1.0f;
            const glm::vec3 offset = rng.uniform() < 0.3 ? rng.vec3(-1e6f, 1e6f) : glm::vec3(0.0f);
            std::vector<Triangle> tris(std::uint32_t(rng.index(90)) + 1);
            // A fan around a shared vertex, so rays through it and along its edges meet several.
            const glm::vec3 hub = offset + rng.vec3(-1.0f, 1.0f) * scale;
            for (std::size_t i = 0; i < tris.size(); ++i) {
                Triangle& t = tris[i];
                if (i > 0 && rng.uniform() < 0.15) {
                    t = tris[rng.index(i)];  // a duplicate under another id
                    continue;
                }
                t.v0 = rng.uniform() < 0.6 ? hub : offset + rng.vec3(-1.0f, 1.0f) * scale;
                t.v1 = offset + rng.vec3(-1.0f, 1.0f) * scale;
                t.v2 = rng.uniform() < 0.1 ? t.v1 : offset + rng.vec3(-1.0f, 1.0f) * scale;  // some have no area
                t.cullBackFace = rng.uniform() < 0.5 ? 1u : 0u;  // the face rule in half the lanes
            }
            std::vector<Ray> rays(40);
            for (Ray& r : rays) {
                const glm::vec3 eye = offset + rng.vec3(-3.0f, 3.0f) * scale;
                const Triangle& aim = tris[rng.index(tris.size())];
                const double pick = rng.uniform();
                const glm::vec3 target = pick < 0.3 ? hub : (pick < 0.5 ? aim.v1 : (pick < 0.7 ? 0.5f * (aim.v0 + aim.v1) : aim.v2));
                glm::dvec3 d = glm::dvec3(target) - glm::dvec3(eye);
                if (glm::length(d) == 0.0) d = {0.0, 0.0, 1.0};
                r = makeRay(eye, glm::normalize(d), rng.uniform() < 0.2 ? rng.uniformFloat(0.0f, 2.0f) * scale : 0.0f);
            }
            std::vector<std::uint32_t> triIds = shuffledIds(rng, std::uint32_t(tris.size()), std::uint32_t(tris.size()));
            triIds.resize(std::min<std::size_t>(triIds.size(), simd::kLeafBatch));
            std::vector<std::uint32_t> rayIds = shuffledIds(rng, std::uint32_t(rays.size()), std::uint32_t(rays.size()));
            std::vector<Hit> expected(rays.size(), missHit()), got(rays.size(), missHit());
            for (std::size_t i = 0; i < rays.size(); ++i)
                if (rng.uniform() < 0.3) expected[i] = got[i] = Hit{rng.uniformFloat(0.0f, 5.0f) * scale, 7, 0.25f, 0.5f};
            for (std::uint32_t id : rayIds)
                for (std::uint32_t prim : triIds) testTriangle(rays[id], tris[prim], prim, expected[id]);
            simd::LeafTriangles batch;
            simd::gatherLeafTriangles(tris.data(), triIds.data(), std::uint32_t(triIds.size()), batch);
            simd::intersectBatch(rays.data(), got.data(), rayIds.data(), std::uint32_t(rayIds.size()), batch);
            for (std::size_t i = 0; i < rays.size(); ++i) {
                if (expected[i].prim != kMissPrim && expected[i].prim != 7) ++hitsFound;
                for (std::uint32_t prim : triIds)
                    if (prim != expected[i].prim && expected[i].prim < tris.size() &&
                        std::memcmp(&tris[prim], &tris[expected[i].prim], sizeof(Triangle)) == 0)
                        ++tiesOnDuplicates;
            }
            for (std::size_t i = 0; i < rays.size(); ++i)
                ASSERT_TRUE(sameHit(got[i], expected[i]))
                    << "trial " << trial << " ray " << i << ": simd prim " << got[i].prim << " t " << got[i].t
                    << ", scalar prim " << expected[i].prim << " t " << expected[i].t;
        }
        EXPECT_GT(hitsFound, 2000u);
        EXPECT_GT(tiesOnDuplicates, 50u);  // the tie rule is exercised, not only distinct depths
    });
}

// The back-face skip of the leaf test (docs/correctness.md, "Back faces skipped in a leaf"):
// rays nearly along a single-sided sheet, leaving it from points on it as occlusion rays do or
// crossing it, at scales and offsets where the roundings of the test are large. Every hit and
// every miss is the scalar test's, both for the closest hit and for any hit. With the skip's
// margin set to 0 the hits differ (tried when it was written: the test's rounding shows a
// front where the normal shows a back).
TEST_F(EveryTarget, LeafBatchSkipsOnlyBackFacesNoRayCanHit) {
    forEachTarget([] {
        Random rng(29);
        std::size_t hitsFound = 0, grazingHits = 0;
        for (int trial = 0; trial < 400; ++trial) {
            const float scale = std::array{1.0f, 1e-3f, 1e4f}[rng.index(3)];
            const glm::vec3 offset = rng.uniform() < 0.4 ? rng.vec3(-1e4f, 1e4f) : glm::vec3(0.0f);
            // A 6x5 grid of points on a sheet, flat (every normal exactly along z) or gently
            // curved, two triangles a cell, counter-clockwise from +z (their fronts face up): 40
            // triangles, a few of them double-sided.
            constexpr int kCols = 6, kRows = 5;
            const double bend = rng.uniform() < 0.5 ? 0.0 : rng.uniform() * 0.3;
            std::vector<glm::vec3> grid;
            for (int r = 0; r < kRows; ++r)
                for (int c = 0; c < kCols; ++c) {
                    const double x = c + 0.2 * rng.uniform(), y = r + 0.2 * rng.uniform();
                    grid.push_back(offset + scale * glm::vec3(float(x), float(y), float(bend * (x * x - y * y) / 8.0)));
                }
            std::vector<Triangle> tris;
            for (int r = 0; r + 1 < kRows; ++r)
                for (int c = 0; c + 1 < kCols; ++c) {
                    const glm::vec3 p00 = grid[r * kCols + c], p10 = grid[r * kCols + c + 1];
                    const glm::vec3 p01 = grid[(r + 1) * kCols + c], p11 = grid[(r + 1) * kCols + c + 1];
                    for (const auto& [a, b, d] : {std::array{p00, p10, p11}, std::array{p00, p11, p01}}) {
                        Triangle t;
                        t.v0 = a;
                        t.v1 = b;
                        t.v2 = d;
                        t.cullBackFace = rng.uniform() < 0.9 ? 1u : 0u;
                        tris.push_back(t);
                    }
                }
            // Half the rays leave the sheet from a point on it, the others cross it at a point
            // inside a triangle; both nearly along it (a normal component of 1e-9 to 1e-2 of
            // the tangent, either side), where the test's rounding decides which face it meets.
            std::vector<Ray> rays(48);
            for (Ray& ray : rays) {
                const Triangle& on = tris[rng.index(tris.size())];
                const double s = rng.uniform(), t = rng.uniform() * (1.0 - s);
                const glm::dvec3 v0(on.v0), e1 = glm::dvec3(on.v1) - v0, e2 = glm::dvec3(on.v2) - v0;
                const glm::dvec3 point = v0 + s * e1 + t * e2;
                const glm::dvec3 normal = glm::normalize(glm::cross(e1, e2));
                glm::dvec3 tangent = glm::cross(normal, rng.onSphere());
                if (glm::length(tangent) < 1e-3) tangent = glm::cross(normal, glm::dvec3(1.0, 0.0, 0.0));
                tangent = glm::normalize(tangent);
                const double lift = std::pow(10.0, -9.0 + 7.0 * rng.uniform()) * (rng.uniform() < 0.5 ? -1.0 : 1.0);
                const glm::dvec3 dir = glm::normalize(tangent + lift * normal);
                const bool crossing = rng.uniform() < 0.5;
                const glm::dvec3 origin = crossing ? point - rng.uniform(0.05, 3.0) * double(scale) * dir : point;
                ray = makeRay(glm::vec3(origin), dir, rng.uniform() < 0.5 ? 1e-4f * scale : 0.0f);
            }
            std::vector<std::uint32_t> triIds = shuffledIds(rng, std::uint32_t(tris.size()), std::uint32_t(tris.size()));
            std::vector<std::uint32_t> rayIds = shuffledIds(rng, std::uint32_t(rays.size()), std::uint32_t(rays.size()));
            simd::LeafTriangles batch;
            simd::gatherLeafTriangles(tris.data(), triIds.data(), std::uint32_t(triIds.size()), batch);
            std::vector<Hit> expected(rays.size(), missHit()), closest(rays.size(), missHit()), any(rays.size(), missHit());
            for (std::uint32_t id : rayIds)
                for (std::uint32_t prim : triIds) testTriangle(rays[id], tris[prim], prim, expected[id]);
            simd::intersectBatch(rays.data(), closest.data(), rayIds.data(), std::uint32_t(rayIds.size()), batch);
            simd::intersectBatch(rays.data(), any.data(), rayIds.data(), std::uint32_t(rayIds.size()), batch, true);
            for (std::size_t i = 0; i < rays.size(); ++i) {
                ASSERT_TRUE(sameHit(closest[i], expected[i]))
                    << "trial " << trial << " ray " << i << ": simd prim " << closest[i].prim << " t " << closest[i].t
                    << ", scalar prim " << expected[i].prim << " t " << expected[i].t;
                ASSERT_EQ(any[i].prim == kMissPrim, expected[i].prim == kMissPrim) << "trial " << trial << " ray " << i;
                if (expected[i].prim == kMissPrim) continue;
                ++hitsFound;
                const glm::dvec3 d(rays[i].dir);
                const Triangle& hit = tris[expected[i].prim];
                const glm::dvec3 n = glm::cross(glm::dvec3(hit.v1) - glm::dvec3(hit.v0), glm::dvec3(hit.v2) - glm::dvec3(hit.v0));
                if (std::abs(glm::dot(glm::normalize(n), d) / glm::length(d)) < 1e-3) ++grazingHits;
            }
        }
        EXPECT_GT(hitsFound, 1000u);
        EXPECT_GT(grazingHits, 200u);  // fronts met at angles the skip's margin decides
    });
}

// The packet bounds made lanes at a time are the scalar fold's on every bounded axis, and the
// same axes go unbounded: direction reciprocals of 0, infinity and NaN mixed in, any count.
TEST_F(EveryTarget, RayBoundsAreTheScalarFold) {
    forEachTarget([] {
        Random rng(31);
        std::size_t unbounded = 0, bounded = 0;
        for (int trial = 0; trial < 2000; ++trial) {
            std::vector<Ray> rays(1 + rng.index(80));
            for (Ray& r : rays) {
                r = randomRay(rng);
                for (int a = 0; a < 3; ++a) {
                    const double pick = rng.uniform();
                    if (pick < 0.01) r.invDir[a] = std::numeric_limits<float>::infinity();
                    else if (pick < 0.02) r.invDir[a] = -std::numeric_limits<float>::infinity();
                    else if (pick < 0.025) r.invDir[a] = std::numeric_limits<float>::quiet_NaN();
                }
            }
            std::vector<std::uint32_t> ids = shuffledIds(rng, std::uint32_t(rays.size()), std::uint32_t(rays.size()));
            ids.resize(1 + rng.index(ids.size()));
            RayPacket expected;
            startPacketBounds(expected);
            for (std::uint32_t id : ids) addToPacketBounds(expected, rays[id].invDir);
            const RayPacket got = simd::boundsOfRays(rays.data(), ids.data(), std::uint32_t(ids.size()));
            ASSERT_EQ(got.unboundedAxes, expected.unboundedAxes) << "trial " << trial;
            for (int a = 0; a < 3; ++a) {
                if ((expected.unboundedAxes >> a) & 1u) {
                    ++unbounded;
                    continue;
                }
                ++bounded;
                ASSERT_EQ(std::bit_cast<std::uint32_t>(got.invLo[a]), std::bit_cast<std::uint32_t>(expected.invLo[a]))
                    << "trial " << trial << " axis " << a;
                ASSERT_EQ(std::bit_cast<std::uint32_t>(got.invHi[a]), std::bit_cast<std::uint32_t>(expected.invHi[a]))
                    << "trial " << trial << " axis " << a;
            }
        }
        EXPECT_GT(unbounded, 500u);
        EXPECT_GT(bounded, 500u);
    });
}

// A leaf's triangles and rays sharing one start, as the group test of a leaf sees them: a fan
// of triangles (some duplicated, some with no area, half single-sided) and rays from the
// start aimed at its hub, its vertices and its edges' midpoints, where a hit lies on the
// triangle's bounds, in an order that keeps aims together (groups of neighbours, as a leaf's
// tile-ordered rays are) or shuffles them.
struct SharedStartLeaf {
    std::vector<Triangle> tris;
    std::vector<Ray> rays;
    std::vector<std::uint32_t> triIds, rayIds;
    float margin = 0.0f;
};

SharedStartLeaf sharedStartLeaf(Random& rng) {
    SharedStartLeaf leaf;
    const float scale = rng.uniform() < 0.3 ? 1e5f : 1.0f;
    const glm::vec3 offset = rng.uniform() < 0.3 ? rng.vec3(-1e6f, 1e6f) : glm::vec3(0.0f);
    leaf.tris.resize(std::uint32_t(rng.index(90)) + 1);
    const glm::vec3 hub = offset + rng.vec3(-1.0f, 1.0f) * scale;
    Box box;
    for (std::size_t i = 0; i < leaf.tris.size(); ++i) {
        Triangle& t = leaf.tris[i];
        if (i > 0 && rng.uniform() < 0.15) {
            t = leaf.tris[rng.index(i)];
        } else {
            t.v0 = rng.uniform() < 0.6 ? hub : offset + rng.vec3(-1.0f, 1.0f) * scale;
            t.v1 = offset + rng.vec3(-1.0f, 1.0f) * scale;
            t.v2 = rng.uniform() < 0.1 ? t.v1 : offset + rng.vec3(-1.0f, 1.0f) * scale;
            // Some axis-aligned: bounds with no extent on an axis, hits on their faces.
            if (rng.uniform() < 0.2) t.v1[rng.index(3)] = t.v0[rng.index(3)], t.v2.y = t.v1.y = t.v0.y;
            t.cullBackFace = rng.uniform() < 0.5 ? 1u : 0u;
        }
        for (const glm::vec3& v : {t.v0, t.v1, t.v2}) box.lo = glm::min(box.lo, v), box.hi = glm::max(box.hi, v);
    }
    const glm::vec3 eye = offset + rng.vec3(-3.0f, 3.0f) * scale;
    const float tmin = rng.uniform() < 0.2 ? rng.uniformFloat(0.0f, 2.0f) * scale : 0.0f;
    leaf.rays.resize(40 + rng.index(200));
    for (std::size_t i = 0; i < leaf.rays.size(); ++i) {
        const Triangle& aim = leaf.tris[rng.index(leaf.tris.size())];
        const double pick = rng.uniform();
        glm::dvec3 target = pick < 0.2 ? glm::dvec3(hub)
                            : pick < 0.4 ? glm::dvec3(aim.v1)
                            : pick < 0.6 ? 0.5 * (glm::dvec3(aim.v0) + glm::dvec3(aim.v1))
                            : pick < 0.8 ? glm::dvec3(aim.v2)
                                         : glm::dvec3(aim.v0) + 0.3 * glm::dvec3(aim.v1 - aim.v0) +
                                               0.3 * glm::dvec3(aim.v2 - aim.v0);
        if (rng.uniform() < 0.3) target += glm::dvec3(rng.onSphere()) * double(scale) * 1e-6;  // beside it
        glm::dvec3 d = target - glm::dvec3(eye);
        if (glm::length(d) == 0.0) d = {0.0, 0.0, 1.0};
        leaf.rays[i] = makeRay(eye, glm::normalize(d), tmin);
    }
    leaf.triIds = shuffledIds(rng, std::uint32_t(leaf.tris.size()), std::uint32_t(leaf.tris.size()));
    leaf.triIds.resize(std::min<std::size_t>(leaf.triIds.size(), simd::kLeafBatch));
    leaf.rayIds = shuffledIds(rng, std::uint32_t(leaf.rays.size()), std::uint32_t(leaf.rays.size()));
    if (rng.uniform() < 0.7)  // neighbours together: ids sorted by direction along one axis
        std::sort(leaf.rayIds.begin(), leaf.rayIds.end(),
                  [&](std::uint32_t a, std::uint32_t b) { return leaf.rays[a].dir.x < leaf.rays[b].dir.x; });
    glm::vec3 farthest = glm::abs(eye);
    leaf.margin = filterMargin(box, farthest);
    return leaf;
}

// The groups narrow a leaf's triangles per group of rays and still find every hit the batch
// finds, bit for bit: the same hits, the same tie winners. With no widening they would miss
// hits on the bounds' faces, which this leaf makes on purpose.
TEST_F(EveryTarget, LeafGroupsGiveTheBatchsHitsBitForBit) {
    forEachTarget([] {
        Random rng(29);
        std::uint64_t tests = 0, skipped = 0, missedWithoutWidening = 0;
        std::size_t hitsFound = 0;
        for (int trial = 0; trial < 400; ++trial) {
            SharedStartLeaf leaf = sharedStartLeaf(rng);
            std::vector<Hit> expected(leaf.rays.size(), missHit());
            for (std::size_t i = 0; i < leaf.rays.size(); ++i)
                if (rng.uniform() < 0.2) expected[i] = Hit{rng.uniformFloat(0.0f, 5.0f), 7, 0.25f, 0.5f};
            std::vector<Hit> got = expected, unwidened = expected;
            for (std::uint32_t id : leaf.rayIds)
                for (std::uint32_t prim : leaf.triIds) testTriangle(leaf.rays[id], leaf.tris[prim], prim, expected[id]);
            simd::LeafTriangles batch;
            simd::gatherLeafTriangles(leaf.tris.data(), leaf.triIds.data(), std::uint32_t(leaf.triIds.size()), batch);
            const std::uint32_t rayCount = std::uint32_t(leaf.rayIds.size());
            skipped += simd::intersectBatchInGroups(leaf.rays.data(), got.data(), leaf.rayIds.data(), rayCount, batch,
                                                    2.0f * leaf.margin);
            simd::intersectBatchInGroups(leaf.rays.data(), unwidened.data(), leaf.rayIds.data(), rayCount, batch, 0.0f);
            tests += std::uint64_t(rayCount) * leaf.triIds.size();
            for (std::size_t i = 0; i < leaf.rays.size(); ++i) {
                ASSERT_TRUE(sameHit(got[i], expected[i]))
                    << "trial " << trial << " ray " << i << ": groups prim " << got[i].prim << " t " << got[i].t
                    << ", scalar prim " << expected[i].prim << " t " << expected[i].t;
                hitsFound += expected[i].prim != kMissPrim && expected[i].prim != 7;
                missedWithoutWidening += !sameHit(unwidened[i], expected[i]);
            }
        }
        EXPECT_GT(hitsFound, 5000u);
        EXPECT_GT(skipped, tests / 20) << "the groups must narrow the leaf, not only keep it";
        EXPECT_GT(missedWithoutWidening, 0u) << "the leaf must hold hits that only the widening keeps";
    });
}

// A leaf's triangles and rays as a secondary pass's leaf holds them: a sheet of triangles on
// a grid, neighbours sharing vertices and edges (some flat, with no extent along z; some
// duplicated, some with no area, half single-sided), and rays with their own starts and
// short segments, in runs of eight at one triangle (neighbouring surface points, as a pass's
// ids are ordered by pixel): each aimed at a vertex, an edge's midpoint or a face point (or
// just beside it) from a start a random distance back along its direction (some with a
// negative tmin), its segment ending exactly there, short of it or past it.
// Hits lie on the triangles' bounds and segments end on them, where only the widening keeps a
// triangle. In some leaves the rays are long enough that their groups' boxes hold the cell,
// and in some their order is shuffled, so that no group is narrow.
struct OwnSegmentLeaf {
    std::vector<Triangle> tris;
    std::vector<Ray> rays;
    std::vector<Hit> start;  // each ray's best before the leaf: a miss at its segment's end
    std::vector<std::uint32_t> triIds, rayIds;
    Box cell;  // the triangles' bounds widened by the margin, as the traversal's leaf cell
    float margin = 0.0f;
};

OwnSegmentLeaf ownSegmentLeaf(Random& rng) {
    OwnSegmentLeaf leaf;
    const float scale = rng.uniform() < 0.3 ? 1e5f : 1.0f;
    const glm::vec3 offset = rng.uniform() < 0.3 ? rng.vec3(-1e6f, 1e6f) : glm::vec3(0.0f);
    const std::uint32_t side = 4 + std::uint32_t(rng.index(3));  // 32 to 72 triangles
    auto grid = [&](std::uint32_t x, std::uint32_t y, float z) {
        return offset + glm::vec3(float(x) / float(side), float(y) / float(side), z) * scale;
    };
    const bool flat = rng.uniform() < 0.3;
    std::vector<float> height((side + 1) * (side + 1));
    for (float& h : height) h = flat ? 0.0f : rng.uniformFloat(-0.1f, 0.1f);
    for (std::uint32_t y = 0; y < side; ++y)
        for (std::uint32_t x = 0; x < side; ++x) {
            auto corner = [&](std::uint32_t cx, std::uint32_t cy) { return grid(cx, cy, height[cy * (side + 1) + cx]); };
            for (int half = 0; half < 2; ++half) {
                Triangle t;
                if (!leaf.tris.empty() && rng.uniform() < 0.1) {
                    t = leaf.tris[rng.index(leaf.tris.size())];  // a duplicate under another id
                } else {
                    t.v0 = corner(x, y);
                    t.v1 = half == 0 ? corner(x + 1, y) : corner(x + 1, y + 1);
                    t.v2 = half == 0 ? corner(x + 1, y + 1) : corner(x, y + 1);
                    if (rng.uniform() < 0.05) t.v2 = t.v1;  // no area
                    t.cullBackFace = rng.uniform() < 0.5 ? 1u : 0u;
                }
                leaf.tris.push_back(t);
            }
        }
    glm::vec3 lo(kNoHitT), hi(-kNoHitT), farthest(0.0f);
    for (const Triangle& t : leaf.tris)
        for (const glm::vec3& v : {t.v0, t.v1, t.v2}) lo = glm::min(lo, v), hi = glm::max(hi, v);
    const float extent = glm::length(hi - lo);
    const bool longRays = rng.uniform() < 0.15;
    leaf.rays.resize(40 + rng.index(200));
    leaf.start.resize(leaf.rays.size());
    // In some leaves each run of a group's size is one ray repeated: its group's box is that
    // ray's segment's alone, which a hit at the segment's end can leave a rounding outside its
    // triangle's bounds (what the widening is for).
    const bool repeated = rng.uniform() < 0.3;
    std::size_t aimed = 0;
    for (std::size_t i = 0; i < leaf.rays.size(); ++i) {
        if (repeated && i % simd::kLeafGroupRays != 0) {
            leaf.rays[i] = leaf.rays[i - 1];
            leaf.start[i] = leaf.start[i - 1];
            continue;
        }
        if (i % 8 == 0) aimed = rng.index(leaf.tris.size());
        const Triangle& aim = leaf.tris[aimed];
        const double pick = rng.uniform();
        glm::dvec3 target = pick < 0.2 ? glm::dvec3(aim.v0)
                            : pick < 0.4 ? glm::dvec3(aim.v1)
                            : pick < 0.55 ? glm::dvec3(aim.v2)
                            : pick < 0.75 ? 0.5 * (glm::dvec3(aim.v0) + glm::dvec3(aim.v2))
                                          : glm::dvec3(aim.v0) + 0.3 * glm::dvec3(aim.v1 - aim.v0) +
                                                0.3 * glm::dvec3(aim.v2 - aim.v0);
        if (rng.uniform() < 0.2) target += glm::dvec3(rng.onSphere()) * double(extent) * 1e-6;  // beside it
        glm::dvec3 dir = rng.onSphere();
        if (rng.uniform() < 0.05) {  // along an axis: zero direction components
            dir = glm::dvec3(0.0);
            dir[rng.index(3)] = rng.uniform() < 0.5 ? 1.0 : -1.0;
        }
        const double back = double(extent) * (longRays ? 4.0 : rng.uniformFloat(0.001f, 0.05f));
        const glm::vec3 origin = glm::vec3(target - dir * back);
        Ray& r = leaf.rays[i];
        r = makeRay(origin, dir, rng.uniform() < 0.1 ? -float(back) : 0.0f);  // no hit behind the origin even so
        const double end = rng.uniform();
        r.tmax = end < 0.03 ? kNoHitT : float(back * (end < 0.5 ? 1.0 : end < 0.75 ? 0.5 : 2.0));  // some whole rays
        leaf.start[i] = missHit(r);
        farthest = glm::max(farthest, glm::abs(origin));
    }
    leaf.margin = filterMargin(Box{lo, hi}, farthest);
    leaf.cell = Box{lo - glm::vec3(leaf.margin), hi + glm::vec3(leaf.margin)};
    leaf.triIds = shuffledIds(rng, std::uint32_t(leaf.tris.size()), std::uint32_t(leaf.tris.size()));
    leaf.triIds.resize(std::min<std::size_t>(leaf.triIds.size(), simd::kLeafBatch));
    leaf.rayIds.resize(leaf.rays.size());
    for (std::uint32_t i = 0; i < leaf.rayIds.size(); ++i) leaf.rayIds[i] = i;
    if (rng.uniform() < 0.15) rng.shuffle(leaf.rayIds);
    return leaf;
}

// The segment groups narrow a leaf's triangles per group of rays with their own segments and
// still find every hit the batch finds: bit for bit for closest hits, ties at a segment's very
// end included; for any hit, a hit exactly where the batch finds one, and a hit the triangle
// itself gives the ray, or the hit the ray already had. With no widening they would miss hits
// at the segments' ends and on the bounds' faces, which this leaf makes on purpose.
TEST_F(EveryTarget, SegmentGroupsGiveTheBatchsHitsBitForBit) {
    forEachTarget([] {
        Random rng(37);
        constexpr std::uint32_t kTieIds[] = {kMissPrim, 0x80000000u, 0u};
        std::uint64_t tests = 0, skipped = 0, missedWithoutWidening = 0;
        std::size_t hitsFound = 0, anyHitsFound = 0, tiesTaken = 0;
        for (int trial = 0; trial < 400; ++trial) {
            const OwnSegmentLeaf leaf = ownSegmentLeaf(rng);
            const std::vector<Hit>& start = leaf.start;
            std::vector<Hit> expected = start;
            for (std::uint32_t id : leaf.rayIds)
                for (std::uint32_t prim : leaf.triIds) testTriangle(leaf.rays[id], leaf.tris[prim], prim, expected[id]);
            simd::LeafTriangles batch;
            simd::gatherLeafTriangles(leaf.tris.data(), leaf.triIds.data(), std::uint32_t(leaf.triIds.size()), batch);
            const Box& cell = leaf.cell;
            const std::uint32_t rayCount = std::uint32_t(leaf.rayIds.size());
            // Closest hits with a best so far at exactly their hit's t (the box's end) under a
            // miss, a high id or id 0: the tie rule must pick the scalar test's winner.
            std::vector<Hit> tieStart = start;
            for (std::size_t i = 0; i < leaf.rays.size(); ++i)
                if (expected[i].prim != kMissPrim)
                    tieStart[i] = Hit{expected[i].t, kTieIds[rng.index(std::size(kTieIds))], 0.25f, 0.5f};
            std::vector<Hit> tieExpected = tieStart, tieGot = tieStart;
            for (std::uint32_t id : leaf.rayIds)
                for (std::uint32_t prim : leaf.triIds)
                    testTriangle(leaf.rays[id], leaf.tris[prim], prim, tieExpected[id]);
            simd::intersectBatchInSegmentGroups(leaf.rays.data(), tieGot.data(), leaf.rayIds.data(),
                                                std::uint32_t(leaf.rayIds.size()), batch, cell, 2.0f * leaf.margin,
                                                false);
            for (std::size_t i = 0; i < leaf.rays.size(); ++i) {
                ASSERT_TRUE(sameHit(tieGot[i], tieExpected[i]))
                    << "trial " << trial << " ray " << i << ": groups prim " << tieGot[i].prim << ", scalar prim "
                    << tieExpected[i].prim << " (tie with " << tieStart[i].prim << ")";
                tiesTaken += tieStart[i].prim != kMissPrim && tieStart[i].prim != 0u &&
                             tieExpected[i].prim != tieStart[i].prim;
            }
            for (bool anyHit : {false, true}) {
                // An any-hit ray that already has a hit keeps it: every fifth one here.
                std::vector<Hit> anyStart = start;
                if (anyHit)
                    for (std::size_t i = 0; i < anyStart.size(); i += 5) anyStart[i] = Hit{start[i].t, 7, 0.25f, 0.5f};
                std::vector<Hit> got = anyStart, unwidened = anyStart;
                skipped += simd::intersectBatchInSegmentGroups(leaf.rays.data(), got.data(), leaf.rayIds.data(),
                                                               rayCount, batch, cell, 2.0f * leaf.margin, anyHit);
                simd::intersectBatchInSegmentGroups(leaf.rays.data(), unwidened.data(), leaf.rayIds.data(), rayCount,
                                                    batch, cell, 0.0f, anyHit);
                tests += std::uint64_t(rayCount) * leaf.triIds.size();
                for (std::size_t i = 0; i < leaf.rays.size(); ++i) {
                    if (anyHit && i % 5 == 0) {
                        ASSERT_TRUE(sameHit(got[i], anyStart[i]))
                            << "trial " << trial << " ray " << i << ": a ray's any hit changed to " << got[i].prim;
                        continue;
                    }
                    missedWithoutWidening += (unwidened[i].prim == kMissPrim) != (expected[i].prim == kMissPrim);
                    if (!anyHit) {
                        ASSERT_TRUE(sameHit(got[i], expected[i]))
                            << "trial " << trial << " ray " << i << ": groups prim " << got[i].prim << " t "
                            << got[i].t << ", scalar prim " << expected[i].prim << " t " << expected[i].t;
                        hitsFound += expected[i].prim != kMissPrim;
                        continue;
                    }
                    ASSERT_EQ(got[i].prim == kMissPrim, expected[i].prim == kMissPrim)
                        << "trial " << trial << " ray " << i << ": any hit " << got[i].prim << ", closest "
                        << expected[i].prim;
                    if (got[i].prim == kMissPrim) continue;
                    ++anyHitsFound;
                    Hit own = start[i];
                    testTriangle(leaf.rays[i], leaf.tris[got[i].prim], got[i].prim, own);
                    ASSERT_TRUE(sameHit(got[i], own)) << "trial " << trial << " ray " << i << ": any hit "
                                                      << got[i].prim << " is not that triangle's hit";
                }
            }
        }
        EXPECT_GT(hitsFound, 3000u);
        EXPECT_GT(anyHitsFound, 3000u);
        EXPECT_GT(tiesTaken, 1000u) << "hits at a segment's very end must take ties from misses and high ids";
        EXPECT_GT(skipped, tests / 5) << "the groups must narrow the leaf, not only keep it";
        EXPECT_GT(missedWithoutWidening, 0u) << "the leaf must hold hits that only the widening keeps";
    });
}

// A triangle hit at exactly the t of the ray's best so far wins by the smaller id, the ids
// compared unsigned (shared::hitPrecedes): it takes the place of a miss ending there
// (kMissPrim) or of a hit whose id is 2^31 or more, and not of a hit with id 0. The groups
// compare ids in signed lanes with their top bits flipped, and the per-ray kernel in scalar
// code: both must give the scalar test's winners. Without the flip, the first two kinds of tie
// go the other way.
TEST_F(EveryTarget, LeafKernelsBreakTiesWithTheIdsAsUnsigned) {
    forEachTarget([] {
        Random rng(31);
        constexpr std::uint32_t kTieIds[] = {kMissPrim, 0x80000000u, 0u};
        std::size_t ties[3] = {}, tiesWon[3] = {};
        for (int trial = 0; trial < 300; ++trial) {
            SharedStartLeaf leaf = sharedStartLeaf(rng);
            std::vector<Hit> truth(leaf.rays.size(), missHit());
            for (std::uint32_t id : leaf.rayIds)
                for (std::uint32_t prim : leaf.triIds) testTriangle(leaf.rays[id], leaf.tris[prim], prim, truth[id]);
            // Each ray that hits starts with a best at its hit's t, under one of the tie ids.
            std::vector<Hit> start(leaf.rays.size(), missHit());
            std::vector<int> kind(leaf.rays.size(), -1);
            for (std::size_t i = 0; i < leaf.rays.size(); ++i)
                if (truth[i].prim != kMissPrim) {
                    kind[i] = int(rng.index(3));
                    start[i] = Hit{truth[i].t, kTieIds[kind[i]], 0.25f, 0.5f};
                }
            std::vector<Hit> expected = start, groups = start, perRay = start;
            for (std::uint32_t id : leaf.rayIds)
                for (std::uint32_t prim : leaf.triIds) testTriangle(leaf.rays[id], leaf.tris[prim], prim, expected[id]);
            simd::LeafTriangles batch;
            simd::gatherLeafTriangles(leaf.tris.data(), leaf.triIds.data(), std::uint32_t(leaf.triIds.size()), batch);
            const std::uint32_t rayCount = std::uint32_t(leaf.rayIds.size());
            simd::intersectBatchInGroups(leaf.rays.data(), groups.data(), leaf.rayIds.data(), rayCount, batch,
                                         2.0f * leaf.margin);
            simd::intersectBatch(leaf.rays.data(), perRay.data(), leaf.rayIds.data(), rayCount, batch);
            for (std::size_t i = 0; i < leaf.rays.size(); ++i) {
                ASSERT_TRUE(sameHit(groups[i], expected[i]))
                    << "trial " << trial << " ray " << i << ": groups prim " << groups[i].prim << ", scalar prim "
                    << expected[i].prim << " (tie with " << start[i].prim << " at t " << start[i].t << ")";
                ASSERT_TRUE(sameHit(perRay[i], expected[i]))
                    << "trial " << trial << " ray " << i << ": per-ray prim " << perRay[i].prim << ", scalar prim "
                    << expected[i].prim << " (tie with " << start[i].prim << " at t " << start[i].t << ")";
                if (kind[i] < 0) continue;
                ++ties[kind[i]];
                tiesWon[kind[i]] += expected[i].prim != start[i].prim;
            }
        }
        // The hit takes the tie from the miss and the high id every time it is the best hit, and
        // never from id 0 unless it is triangle 0.
        EXPECT_EQ(tiesWon[0], ties[0]);
        EXPECT_EQ(tiesWon[1], ties[1]);
        EXPECT_LT(tiesWon[2], ties[2] / 4);
        EXPECT_GT(ties[0], 1000u);
        EXPECT_GT(ties[1], 1000u);
    });
}

// The packets' tile sort gives what a stable sort of the ids by 8x8 tile gives, and each
// tile's end, on widths that are not multiples of 8 (the last column of tiles narrower: a
// run of ids stops at the row's end) as on those that are: ids in runs in pixel order (as a
// frame starts), in runs whose order is shuffled (as the partitions leave them), and one by
// one in any order, each with pixels left out.
TEST(PacketTiles, SortedAsAStableSortByTileOnEveryWidth) {
    Random rng(37);
    std::size_t cases = 0;
    for (const std::uint32_t width : {1u, 3u, 7u, 8u, 9u, 13u, 16u, 21u, 64u, 67u})
        for (int trial = 0; trial < 40; ++trial) {
            const std::uint32_t height = 1 + std::uint32_t(rng.index(20));
            const std::uint32_t tilesX = (width + kPacketTile - 1) / kPacketTile;
            const std::uint32_t tiles = tilesX * ((height + kPacketTile - 1) / kPacketTile);
            const double keep = trial % 4 == 0 ? 1.0 : rng.uniformFloat(0.2f, 0.95f);
            std::vector<std::uint32_t> ids;
            for (std::uint32_t id = 0; id < width * height; ++id)
                if (rng.uniform() < keep) ids.push_back(id);
            if (trial % 3 == 1) {  // runs of up to 20 ids, their order shuffled
                std::vector<std::vector<std::uint32_t>> runs;
                for (std::size_t k = 0; k < ids.size();) {
                    const std::size_t length = std::min(ids.size() - k, std::size_t(1 + rng.index(20)));
                    runs.emplace_back(ids.begin() + std::ptrdiff_t(k), ids.begin() + std::ptrdiff_t(k + length));
                    k += length;
                }
                for (std::size_t k = runs.size(); k > 1; --k) std::swap(runs[k - 1], runs[rng.index(k)]);
                ids.clear();
                for (const auto& run : runs) ids.insert(ids.end(), run.begin(), run.end());
            } else if (trial % 3 == 2) {
                for (std::size_t k = ids.size(); k > 1; --k) std::swap(ids[k - 1], ids[rng.index(k)]);
            }
            auto tileOf = [&](std::uint32_t id) {
                return (id / width) / kPacketTile * tilesX + (id % width) / kPacketTile;
            };
            std::vector<std::uint32_t> expected = ids;
            std::stable_sort(expected.begin(), expected.end(),
                             [&](std::uint32_t a, std::uint32_t b) { return tileOf(a) < tileOf(b); });
            std::vector<std::uint32_t> sorted(ids.size(), 0xFFFFFFFFu), ends(tiles + 1, 0xFFFFFFFFu);
            sortRaysByTile(ids.data(), std::uint32_t(ids.size()), width, tiles, ends.data(), sorted.data());
            ASSERT_EQ(sorted, expected) << "width " << width << " height " << height << " trial " << trial;
            std::uint32_t end = 0;
            for (std::uint32_t t = 0; t < tiles; ++t) {
                while (end < expected.size() && tileOf(expected[end]) == t) ++end;
                ASSERT_EQ(ends[t], end) << "width " << width << " height " << height << " trial " << trial << " tile " << t;
            }
            ++cases;
        }
    EXPECT_EQ(cases, 400u);
}

// A packet's answer covers every one of its rays' answers (with no best hit yet), and it
// still rejects: rays sharing a start, directions within a small cone, random cells.
TEST(PacketFilter, NeverRejectsACellOneOfItsRaysMayCross) {
    Random rng(15);
    std::size_t rejected = 0, trials = 0;
    for (int trial = 0; trial < 3000; ++trial) {
        const glm::vec3 origin{adversarialCoordinate(rng), adversarialCoordinate(rng), adversarialCoordinate(rng)};
        const float tmin = rng.uniform() < 0.3 ? rng.uniformFloat(0.0f, 1.0f) : 0.0f;
        const glm::dvec3 axis = rng.onSphere();
        const double spread = rng.uniform() < 0.5 ? 0.05 : 0.5;
        std::vector<Ray> rays(1 + rng.index(64));
        for (Ray& r : rays) {
            glm::dvec3 d = axis + spread * rng.onSphere();
            for (int a = 0; a < 3; ++a)
                if (rng.uniform() < 0.05) d[a] = 0.0;  // a component exactly 0: that axis goes unbounded
            if (d == glm::dvec3(0.0)) d = axis;
            r = makeRay(origin, d, tmin);
        }
        RayPacket p;
        p.invLo = glm::vec3(kNoHitT);
        p.invHi = glm::vec3(-kNoHitT);
        for (const Ray& r : rays)
            for (int a = 0; a < 3; ++a) {
                if (r.invDir[a] == 0.0f) p.unboundedAxes |= 1u << a;
                p.invLo[a] = std::min(p.invLo[a], r.invDir[a]);
                p.invHi[a] = std::max(p.invHi[a], r.invDir[a]);
            }
        const Box cell = randomCell(rng);
        bool anyRay = false;
        for (const Ray& r : rays) anyRay |= shared::rayMayCrossCell(r, cell.lo, cell.hi, kNoHitT);
        const bool packet = packetMayCrossCell(p, origin, tmin, cell);
        if (anyRay) {
            ASSERT_TRUE(packet) << "trial " << trial;
        }
        rejected += !packet;
        ++trials;
    }
    EXPECT_GT(rejected, trials / 5) << "the packet test must reject cells, not only keep them";
}

TEST(SimdTargets, TheBestIsChosenByDefaultAndForcingAnUnknownOneIsAnError) {
    simd::forceTarget("");
    const std::vector<std::string> targets = simd::availableTargets();
    ASSERT_FALSE(targets.empty());
    EXPECT_EQ(simd::activeTarget(), targets.front());
    EXPECT_THROW(simd::forceTarget("no-such-target"), std::invalid_argument);
    simd::forceTarget("");
    EXPECT_EQ(simd::activeTarget(), targets.front());
}

TEST_F(EveryTarget, FacingVerdictsNeverContradictTheFloat64Skip) {
    // Triangles at every distance, size and slant (nearly edge-on ones, tiny and huge ones,
    // some double-sided): a certified verdict is always facesAwayFrom's, and most are certified.
    forEachTarget([] {
        Random rng(5);
        std::size_t certified = 0, dropped = 0, total = 0;
        for (int round = 0; round < 40; ++round) {
            const glm::vec3 origin = rng.vec3(-10.0f, 10.0f) * (round % 4 == 3 ? 1e6f : 1.0f);
            std::vector<Triangle> tris(std::size_t(rng.index(200)) + 1);
            for (Triangle& t : tris) {
                const double distance = std::pow(10.0, rng.uniform(-12.0, 8.0));
                const glm::dvec3 centre = glm::dvec3(origin) + distance * glm::normalize(rng.inBox(-1.0, 1.0) + 1e-9);
                const double size = distance * std::pow(10.0, rng.uniform(-7.0, 0.5));
                glm::dvec3 p[3];
                for (glm::dvec3& q : p) q = centre + size * rng.inBox(-1.0, 1.0);
                if (rng.uniform() < 0.3) {  // nearly edge-on from the origin
                    const glm::dvec3 n = glm::normalize(glm::cross(centre - glm::dvec3(origin), p[1] - p[0]));
                    const double squeeze = std::pow(10.0, rng.uniform(-9.0, -1.0));
                    for (glm::dvec3& q : p) q -= (1.0 - squeeze) * glm::dot(q - glm::dvec3(origin), n) * n;
                }
                t.v0 = glm::vec3(p[0]);
                t.v1 = glm::vec3(p[1]);
                t.v2 = glm::vec3(p[2]);
                t.cullBackFace = rng.uniform() < 0.9 ? 1u : 0u;
            }
            std::vector<std::uint8_t> verdict(tris.size(), 0xFF);
            simd::classifyFacing(tris.data(), std::uint32_t(tris.size()), origin, verdict.data());
            for (std::size_t i = 0; i < tris.size(); ++i) {
                const bool away = tris[i].cullBackFace && facesAwayFrom(tris[i], glm::dvec3(origin));
                ASSERT_NE(verdict[i], 0xFF) << "every verdict written";
                if (verdict[i] == simd::kUndecided) continue;
                ++certified;
                dropped += away;
                ASSERT_EQ(verdict[i] == simd::kDrop, away) << "round " << round << ", triangle " << i;
            }
            total += tris.size();
        }
        // This mix is mostly extreme on purpose (lengths down to 1e-12, edge-on slivers).
        EXPECT_GT(certified, total * 4 / 10);
        EXPECT_GT(dropped, total / 10);
    });
}

TEST_F(EveryTarget, FacingVerdictsDoNotDependOnTheLane) {
    // Each triangle classified alone (every lane holding it) and among its neighbours, at each
    // lane position and in a short last group: the same verdict, so the lanes take their own
    // triangle's floats and cullBackFace word.
    forEachTarget([] {
        Random rng(11);
        const glm::vec3 origin = rng.vec3(-2.0f, 2.0f);
        std::vector<Triangle> tris(16 * 5 + 7);
        for (Triangle& t : tris) {
            const glm::vec3 centre = rng.vec3(-5.0f, 5.0f);
            t.v0 = centre + rng.vec3(-1.0f, 1.0f);
            t.v1 = centre + rng.vec3(-1.0f, 1.0f);
            t.v2 = centre + rng.vec3(-1.0f, 1.0f);
            t.cullBackFace = rng.uniform() < 0.8 ? 1u : 0u;
        }
        std::vector<std::uint8_t> together(tris.size());
        simd::classifyFacing(tris.data(), std::uint32_t(tris.size()), origin, together.data());
        std::size_t decided = 0;
        for (std::size_t i = 0; i < tris.size(); ++i) {
            std::uint8_t alone = 0xFF;
            simd::classifyFacing(&tris[i], 1, origin, &alone);
            ASSERT_EQ(together[i], alone) << "triangle " << i;
            decided += alone != simd::kUndecided;
        }
        EXPECT_GT(decided, tris.size() / 2);
    });
}

namespace {

// A pass cull's grid of any shape: its axes a rotation of the scene's, 1 to 128 cells along
// each (one in five axes a single cell), flat axes (scale 0) among them.
simd::GridAxes randomGrid(Random& rng) {
    simd::GridAxes grid;
    const int first = int(rng.index(3));
    for (int k = 0; k < 3; ++k) {
        grid.axis[k] = (first + k) % 3;
        grid.count[k] = rng.uniform() < 0.2 ? 1 : int(rng.index(128)) + 1;
        grid.lo[k] = adversarialCoordinate(rng);
        grid.scale[k] = rng.uniform() < 0.15 ? 0.0f : float(grid.count[k]) / rng.uniformFloat(0.01f, 4.0f);
    }
    return grid;
}

}  // namespace

TEST_F(EveryTarget, BoxCellsAreTheGridRulesCells) {
    // Grids of every shape (flat axes of scale 0, one cell, 128) and boxes on cell faces, far
    // outside the grid and infinite: every cell is cellAlong's, for every count of a block.
    forEachTarget([] {
        Random rng(11);
        std::size_t clamped = 0, inside = 0;
        for (int round = 0; round < 60; ++round) {
            const simd::GridAxes grid = randomGrid(rng);
            const int first = grid.axis[0];
            const auto count = std::uint32_t(rng.index(simd::kCullBlock)) + 1;
            std::vector<Bounds> bounds(count);
            for (Bounds& b : bounds) {
                const Box box = randomCell(rng);
                b.lo = box.lo;
                b.hi = box.hi;
                for (int a = 0; a < 3; ++a) {
                    const int k = (a - first + 3) % 3;  // the grid axis of scene axis a
                    const double u = rng.uniform();
                    if (u < 0.2 && grid.scale[k] > 0.0f)  // on a cell face
                        b.lo[a] = grid.lo[k] + float(rng.index(std::size_t(grid.count[k]) + 1)) / grid.scale[k];
                    else if (u < 0.25)
                        b.lo[a] = -std::numeric_limits<float>::infinity();
                    else if (u < 0.3)
                        b.hi[a] = std::numeric_limits<float>::infinity();
                    b.hi[a] = std::max(b.hi[a], b.lo[a]);
                }
            }
            simd::BoxCells cells;
            for (auto& side : {&cells.first, &cells.last})
                for (auto& axis : *side) std::fill(std::begin(axis), std::end(axis), -7);
            simd::cellsOfBoxes(bounds.data(), count, grid, cells);
            for (std::uint32_t i = 0; i < count; ++i)
                for (int k = 0; k < 3; ++k) {
                    const int lo = simd::cellAlong(grid, bounds[i].lo[grid.axis[k]], k);
                    const int hi = simd::cellAlong(grid, bounds[i].hi[grid.axis[k]], k);
                    ASSERT_EQ(cells.first[k][i], lo) << "round " << round << ", box " << i << ", axis " << k;
                    ASSERT_EQ(cells.last[k][i], hi) << "round " << round << ", box " << i << ", axis " << k;
                    clamped += (lo == 0) + (hi == grid.count[k] - 1);
                    inside += (lo > 0 && lo < grid.count[k] - 1) + (hi > 0 && hi < grid.count[k] - 1);
                }
        }
        EXPECT_GT(clamped, 1000u) << "few boxes reach the grid's ends";
        EXPECT_GT(inside, 1000u) << "few boxes end inside the grid";
    });
}

namespace {

// One of the two adjacent doubles between which facesAwayAlong(t, direction, reach) turns
// false as the reach grows (it falls with the reach): a lane that rounds any step otherwise
// than the rule answers differently there, one time in a few. False where t is never away.
bool thresholdReach(const Triangle& t, const glm::dvec3& direction, bool above, double& reach) {
    if (!t.cullBackFace) return false;
    std::int64_t lo = std::bit_cast<std::int64_t>(1e-30), hi = std::bit_cast<std::int64_t>(1e30);
    if (!facesAwayAlong(t, direction, std::bit_cast<double>(lo)) || facesAwayAlong(t, direction, std::bit_cast<double>(hi)))
        return false;
    while (hi - lo > 1) {  // positive doubles are ordered as their bits
        const std::int64_t mid = lo + (hi - lo) / 2;
        (facesAwayAlong(t, direction, std::bit_cast<double>(mid)) ? lo : hi) = mid;
    }
    reach = std::bit_cast<double>(above ? hi : lo);
    return true;
}

}  // namespace

TEST_F(EveryTarget, FacingAlongADirectionIsTheFloat64Rule) {
    // Triangles of every size and slant against a direction, some nearly edge-on to it, and in
    // half the rounds a reach on either side of the first triangle's threshold:
    // every asked lane is facesAwayAlong's answer (single-sided ones only), and no lane of a
    // vector none of whose lanes was asked is set.
    forEachTarget([] {
        Random rng(13);
        std::size_t away = 0, kept = 0, onThreshold = 0;
        for (int round = 0; round < 400; ++round) {
            const glm::dvec3 direction = rng.onSphere() * std::pow(10.0, rng.uniform(-3.0, 3.0));
            const auto count = std::uint32_t(rng.index(simd::kCullBlock)) + 1;
            std::vector<Triangle> tris(count);
            for (Triangle& t : tris) {
                const glm::dvec3 centre = rng.inBox(-1.0, 1.0) * std::pow(10.0, rng.uniform(-3.0, 5.0));
                const double size = std::pow(10.0, rng.uniform(-6.0, 2.0));
                glm::dvec3 p[3];
                for (glm::dvec3& q : p) q = centre + size * rng.inBox(-1.0, 1.0);
                if (rng.uniform() < 0.5) {  // nearly edge-on to the direction
                    const glm::dvec3 n = glm::normalize(glm::cross(direction, p[1] - p[0]));
                    const double squeeze = std::pow(10.0, rng.uniform(-9.0, -1.0));
                    for (glm::dvec3& q : p) q -= (1.0 - squeeze) * glm::dot(q - centre, n) * n;
                }
                t.v0 = glm::vec3(p[0]);
                t.v1 = glm::vec3(p[1]);
                t.v2 = glm::vec3(p[2]);
                t.cullBackFace = rng.uniform() < 0.8 ? 1u : 0u;
            }
            double reach = std::pow(10.0, rng.uniform(-2.0, 6.0));
            if (round % 2 == 1) {
                tris[0].cullBackFace = 1u;
                if (!thresholdReach(tris[0], direction, rng.uniform() < 0.5, reach)) {
                    std::swap(tris[0].v1, tris[0].v2);  // its other face
                    onThreshold += thresholdReach(tris[0], direction, rng.uniform() < 0.5, reach);
                } else {
                    ++onThreshold;
                }
            }
            std::vector<std::uint8_t> asked(count), answer(count, 0xFF);
            const bool everyLane = round % 2 == 0;
            for (std::uint8_t& a : asked) a = rng.uniform() < 0.3;
            simd::facingAwayAlong(tris.data(), count, direction, reach, everyLane ? nullptr : asked.data(), answer.data());
            const std::uint32_t lanes = 16;  // a multiple of every target's double lanes
            for (std::uint32_t i = 0; i < count; ++i) {
                ASSERT_LE(answer[i], 1u) << "every answer written, 0 or 1";
                const bool rule = tris[i].cullBackFace && facesAwayAlong(tris[i], direction, reach);
                if (everyLane || asked[i]) {
                    ASSERT_EQ(answer[i] == 1, rule) << "round " << round << ", triangle " << i;
                    (rule ? away : kept) += 1;
                } else {
                    bool anyAsked = false;
                    for (std::uint32_t j = i / lanes * lanes; j < std::min(count, (i / lanes + 1) * lanes); ++j)
                        anyAsked = anyAsked || asked[j];
                    if (!anyAsked) {
                        ASSERT_EQ(answer[i], 0u) << "a lane of a vector none asked for";
                    }
                }
            }
        }
        EXPECT_GT(away, 2000u);
        EXPECT_GT(kept, 2000u);
        EXPECT_GT(onThreshold, 150u);
    });
}

TEST_F(EveryTarget, PieceEndCellsAreTheGridRulesCells) {
    // Segments of every length and direction (axis-parallel ones, ends far outside the grid),
    // cut in 1 to kMostPieces pieces, over grids of every shape: each end's cells are those of
    // the rule (pieceEnd, floatBelow / floatAbove, cellAlong), bounds bit for bit, and
    // floatBelow steps often.
    forEachTarget([] {
        Random rng(17);
        std::size_t ends = 0, stepped = 0;
        for (int round = 0; round < 300; ++round) {
            const simd::GridAxes grid = randomGrid(rng);
            const Ray ray = randomRay(rng);
            const glm::dvec3 origin(ray.origin), dir(ray.dir);
            const double t0 = rng.uniform() < 0.3 ? 0.0 : rng.uniform(-3.0, 3.0);
            const double t1 = t0 + (rng.uniform() < 0.1 ? 0.0 : std::pow(10.0, rng.uniform(-6.0, 3.0)));
            const int pieces = rng.uniform() < 0.1 ? simd::kMostPieces : int(rng.index(40)) + 1;
            const double grow = rng.uniform() < 0.2 ? 0.0 : std::pow(10.0, rng.uniform(-9.0, 0.0));
            simd::PieceEndCells cells;
            simd::cellsNearPieceEnds(origin, dir, t0, t1, pieces, grow, grid, cells);
            for (int e = 0; e <= pieces; ++e) {
                const glm::dvec3 p = origin + simd::pieceEnd(t0, t1, e, pieces) * dir;
                for (int k = 0; k < 3; ++k) {
                    const double x = p[grid.axis[k]];
                    const float below = simd::floatBelow(x - grow), above = simd::floatAbove(x + grow);
                    ASSERT_EQ(std::bit_cast<std::uint32_t>(cells.below[k][e]), std::bit_cast<std::uint32_t>(below))
                        << "round " << round << ", end " << e << " of " << pieces << ", axis " << k;
                    ASSERT_EQ(std::bit_cast<std::uint32_t>(cells.above[k][e]), std::bit_cast<std::uint32_t>(above))
                        << "round " << round << ", end " << e << " of " << pieces << ", axis " << k;
                    ASSERT_EQ(cells.from[k][e], simd::cellAlong(grid, simd::floatBelow(x - grow), k))
                        << "round " << round << ", end " << e << " of " << pieces << ", axis " << k;
                    ASSERT_EQ(cells.to[k][e], simd::cellAlong(grid, simd::floatAbove(x + grow), k))
                        << "round " << round << ", end " << e << " of " << pieces << ", axis " << k;
                    stepped += double(float(x - grow)) > x - grow;
                }
                ++ends;
            }
        }
        EXPECT_GT(ends, 10000u);
        EXPECT_GT(stepped, ends / 4) << "floatBelow's step is seldom taken: the test proves little";
    });
}

TEST(FloatBounds, AreTheNearestFloatsOnTheirSide) {
    Random rng(19);
    for (int i = 0; i < 100000; ++i) {
        const double x = rng.uniform(-1.0, 1.0) * std::pow(10.0, rng.uniform(-40.0, 39.0));
        const float below = simd::floatBelow(x), above = simd::floatAbove(x);
        ASSERT_LE(double(below), x);
        ASSERT_GE(double(above), x);
        ASSERT_GT(double(std::nextafter(below, std::numeric_limits<float>::infinity())), x) << x;
        ASSERT_LT(double(std::nextafter(above, -std::numeric_limits<float>::infinity())), x) << x;
    }
    EXPECT_EQ(simd::floatBelow(0.0), 0.0f);
    EXPECT_EQ(simd::floatBelow(1e300), std::numeric_limits<float>::max());
    EXPECT_EQ(simd::floatAbove(-1e300), -std::numeric_limits<float>::max());
}
