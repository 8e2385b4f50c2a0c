// The cpu backend's image bands: where they begin (equal shares of the estimated work), and
// the triangles each band's rays can reach (none dropped that a ray of the band hits), so that
// the bands give brute force's hits bit for bit.
#include <gtest/gtest.h>

#include "core/errors.hpp"
#include "core/procedural.hpp"
#include "core/random.hpp"
#include "cpu/cpu_tracers.hpp"
#include "cpu/image_bands.hpp"
#include "cpu/traversal.hpp"
#include "cpu/triangle_skips.hpp"
#include "support/frames.hpp"
#include "support/simd_targets.hpp"

using namespace dacrt;
using namespace dacrt::test;

namespace {

Camera tiltedCamera() {
    Camera camera;
    camera.eye = glm::dvec3(0.3, -0.2, 4.0);
    camera.forward = glm::normalize(glm::dvec3(0.1, 0.05, -1.0));
    camera.up = glm::normalize(glm::cross(glm::cross(camera.forward, glm::dvec3(0, 1, 0)), camera.forward));
    camera.yfovRadians = glm::radians(50.0);
    return camera;
}

Triangle doubleSided(const glm::vec3& a, const glm::vec3& b, const glm::vec3& c) {
    Triangle t{};
    t.v0 = a;
    t.v1 = b;
    t.v2 = c;
    return t;
}

Bounds boundsOf(const Triangle& t) {
    Bounds b{};
    b.lo = glm::min(glm::min(t.v0, t.v1), t.v2);
    b.hi = glm::max(glm::max(t.v0, t.v1), t.v2);
    return b;
}

// Every tail length of a vector of up to 16 lanes (1 to 17 boxes), then all of them.
std::vector<std::uint32_t> countsToTry(std::uint32_t all) {
    std::vector<std::uint32_t> counts;
    for (std::uint32_t c = 1; c <= 17 && c <= all; ++c) counts.push_back(c);
    counts.push_back(all);
    return counts;
}

// Rays through the pixels' centres and corners: a band's frustum bounds them all.
const glm::dvec2 kPixelPoints[] = {{0.5, 0.5}, {0.0, 0.0}, {1.0, 1.0}, {0.0, 1.0}, {1.0, 0.0}};

}  // namespace

// The frustum of every row is the view frustum, bit for bit; a band's bottom and top planes
// hold every ray of its rows, at any point of their pixels, to within the rays' rounding.
TEST(RowsFrustum, OfEveryRowIsTheViewFrustumAndHoldsItsRowsRays) {
    const Camera camera = tiltedCamera();
    const int w = 40, h = 30;
    const ViewFrustum f = *viewFrustum(camera, w, h);
    const ViewFrustum all = rowsFrustum(f, 0, h);
    for (std::size_t k = 0; k < 4; ++k)
        for (int a = 0; a < 3; ++a) EXPECT_EQ(all.inward[k][a], f.inward[k][a]) << "plane " << k << " axis " << a;
    for (const glm::dvec2 offset : kPixelPoints) {
        const std::vector<Ray> rays = primaryRays(camera, w, h, offset);
        for (const auto& [first, end] : {std::pair{0, 1}, std::pair{3, 11}, std::pair{14, 15}, std::pair{29, 30}}) {
            const ViewFrustum band = rowsFrustum(f, first, end);
            int insideBoth = 0;
            for (int y = 0; y < h; ++y)
                for (int x = 0; x < w; ++x) {
                    const glm::dvec3 d(rays[std::size_t(y * w + x)].dir);
                    const double below = glm::dot(band.inward[2], d), above = glm::dot(band.inward[3], d);
                    if (y >= first && y < end) {
                        EXPECT_GT(below, -0x1p-22) << "row " << y << " below its band " << first << "-" << end;
                        EXPECT_GT(above, -0x1p-22) << "row " << y << " above its band " << first << "-" << end;
                    } else {
                        insideBoth += below > 0x1p-22 && above > 0x1p-22;
                    }
                }
            EXPECT_EQ(insideBoth, 0) << "a ray of another row inside band " << first << "-" << end;
        }
    }
}

// Double-sided triangles scattered about the edges of a band of rows, many straddling them:
// brute force over every triangle never reports, for a ray of the band, one that the band
// drops (the same argument as the view frustum skip's: Skips.AFrustumDrop...).
TEST(ImageBands, ARowsDropIsNeverATriangleARayOfTheRowsHits) {
    Random rng(12);
    const Camera camera = tiltedCamera();
    const int w = 48, h = 32;
    const ViewFrustum f = *viewFrustum(camera, w, h);
    const glm::dvec3 right = glm::normalize(glm::cross(camera.forward, camera.up));
    const double y = std::tan(0.5 * camera.yfovRadians), x = y * w / h;
    const int first = 8, end = 20;  // the band's rows
    const BandEdges edges(f, {0, std::uint32_t(first), std::uint32_t(end), std::uint32_t(h)});
    std::vector<Triangle> tris;
    for (int i = 0; i < 3000; ++i) {
        // A point on one of the band's edges (or any row) at some depth, a triangle about it.
        const double depth = std::pow(10.0, rng.uniform(-1.0, 2.0));
        const int edgeRow = i % 3 == 0 ? first : i % 3 == 1 ? end : int(rng.uniform(0.0, h));
        const double sy = (1.0 - 2.0 * edgeRow / h) * y, sx = rng.uniform(-x, x);
        const glm::dvec3 c = camera.eye + depth * (camera.forward + sx * right + sy * camera.up);
        const double size = depth * std::pow(10.0, rng.uniform(-4.0, -1.0));
        tris.push_back(doubleSided(glm::vec3(c + size * rng.inBox(-1, 1)), glm::vec3(c + size * rng.inBox(-1, 1)),
                                   glm::vec3(c + size * rng.inBox(-1, 1))));
    }
    std::vector<bool> outside(tris.size());
    std::size_t dropped = 0;
    for (std::size_t i = 0; i < tris.size(); ++i) {
        const auto [firstBand, lastBand] = edges.bandsOf(boundsOf(tris[i]));
        dropped += outside[i] = !(firstBand <= 1 && lastBand >= 1);
    }
    EXPECT_GT(dropped, 400u);
    EXPECT_LT(dropped, tris.size() - 600);
    std::size_t nearMisses = 0;  // dropped triangles a ray of the band passes within a pixel of
    for (const glm::dvec2 offset : kPixelPoints) {
        const std::vector<Ray> rays = primaryRays(camera, w, h, offset);
        for (int row = std::max(0, first - 1); row < std::min(h, end + 1); ++row)
            for (int col = 0; col < w; ++col) {
                const Ray& r = rays[std::size_t(row * w + col)];
                for (std::size_t i = 0; i < tris.size(); ++i) {
                    if (!outside[i]) continue;
                    Hit best = missHit();
                    testTriangle(r, tris[i], std::uint32_t(i), best);
                    if (row >= first && row < end)
                        ASSERT_EQ(best.prim, kMissPrim) << "triangle " << i << " dropped but hit from row " << row;
                    else
                        nearMisses += best.prim != kMissPrim;
                }
            }
    }
    EXPECT_GT(nearMisses, 0u) << "the rows next to the band hit some of what it drops";
}

// The lanes' bands (BandEdges::bandsOfEach, every compiled instruction set) are bandsOf's for
// every box: boxes about the edges of many bands at every depth, boxes behind the camera (which
// can lie beyond edges on both sides), through a list of ids and without one, every tail length.
TEST_F(OnEveryTarget, BandsInLanesAreTheScalarBands) {
    const Camera camera = tiltedCamera();
    const int w = 48, h = 64;
    const ViewFrustum f = *viewFrustum(camera, w, h);
    const std::vector<std::uint32_t> startRows = {0, 5, 8, 20, 21, 40, 63, std::uint32_t(h)};
    const BandEdges edges(f, startRows);
    const glm::dvec3 right = glm::normalize(glm::cross(camera.forward, camera.up));
    const double y = std::tan(0.5 * camera.yfovRadians), x = y * w / h;
    forEachTarget([&] {
        Random rng(33);
        std::vector<Bounds> bounds;
        for (int i = 0; i < 5000; ++i) {
            const double depth = (i % 7 == 0 ? -1.0 : 1.0) * std::pow(10.0, rng.uniform(-1.0, 2.0));
            const int edgeRow = i % 2 ? int(startRows[1 + rng.index(startRows.size() - 2)]) : int(rng.uniform(0.0, h));
            const double sy = (1.0 - 2.0 * edgeRow / h) * y, sx = rng.uniform(-x, x);
            const glm::dvec3 c = camera.eye + depth * (camera.forward + sx * right + sy * camera.up);
            const double size = std::abs(depth) * std::pow(10.0, rng.uniform(-6.0, -0.5));
            const glm::vec3 p(c + size * rng.inBox(-1, 1)), q(c + size * rng.inBox(-1, 1));
            Bounds b{};
            b.lo = glm::min(p, q);
            b.hi = glm::max(p, q);
            bounds.push_back(b);
        }
        // Boxes at a band edge's threshold: a box moved along the edge's normal, by bisection,
        // to the last float step where bandsOf's answer changes, and the box on each side of it.
        // One rounding more or less in a lane's sums changes some of their answers.
        std::size_t thresholds = 0;
        for (int i = 0; i < 400; ++i) {
            const std::uint32_t k = 1 + std::uint32_t(rng.index(startRows.size() - 2));
            const glm::dvec3 normal = rowsFrustum(f, 0, int(startRows[k])).inward[2];
            const double depth = std::pow(10.0, rng.uniform(-1.0, 2.0));
            const double sy = (1.0 - 2.0 * double(startRows[k]) / h) * y, sx = rng.uniform(-x, x);
            const glm::dvec3 c = camera.eye + depth * (camera.forward + sx * right + sy * camera.up);
            const glm::dvec3 half = depth * std::pow(10.0, rng.uniform(-5.0, -1.0)) * rng.inBox(0.1, 1);
            auto boxAt = [&](double t) {
                Bounds b{};
                b.lo = glm::vec3(c - half + t * normal);
                b.hi = glm::vec3(c + half + t * normal);
                return b;
            };
            double a = -4.0 * glm::length(half) - 1e-3 * depth, z = -a;
            if (edges.bandsOf(boxAt(a)) == edges.bandsOf(boxAt(z))) continue;
            for (int step = 0; step < 80; ++step) {
                const double m = 0.5 * (a + z);
                (edges.bandsOf(boxAt(m)) == edges.bandsOf(boxAt(a)) ? a : z) = m;
            }
            bounds.push_back(boxAt(a));
            bounds.push_back(boxAt(z));
            ++thresholds;
        }
        EXPECT_GT(thresholds, 300u);
        std::vector<std::uint32_t> ids;
        for (std::uint32_t i = 0; i < bounds.size(); i += 1 + std::uint32_t(rng.index(3))) ids.push_back(i);
        std::size_t several = 0, one = 0;  // every box reaches a band: the image's own edges are not tested
        for (const bool throughIds : {false, true})
            for (std::uint32_t count : countsToTry(throughIds ? std::uint32_t(ids.size()) : std::uint32_t(bounds.size()))) {
                std::vector<std::uint32_t> first(count), last(count);
                edges.bandsOfEach(bounds.data(), throughIds ? ids.data() : nullptr, count, first.data(), last.data());
                for (std::uint32_t i = 0; i < count; ++i) {
                    const auto [f0, l0] = edges.bandsOf(bounds[throughIds ? ids[i] : i]);
                    ASSERT_EQ(first[i], f0) << "box " << i << (throughIds ? " by id" : "");
                    ASSERT_EQ(last[i], l0) << "box " << i << (throughIds ? " by id" : "");
                    one += f0 == l0;
                    several += f0 < l0;
                }
            }
        EXPECT_GT(one, 1000u);
        EXPECT_GT(several, 1000u);
    });
}

TEST(ImageBands, SplitTheEstimatedWorkIntoEqualShares) {
    EXPECT_EQ(bandsOfEqualWork(std::vector<double>(12, 1.0), 4), (std::vector<std::uint32_t>{0, 3, 6, 9, 12}));
    EXPECT_EQ(bandsOfEqualWork(std::vector<double>(3, 1.0), 5), (std::vector<std::uint32_t>{0, 1, 2, 3}))
        << "at most a band a row";
    // The work in the last rows: the first band takes the rows up to half of it.
    EXPECT_EQ(bandsOfEqualWork({1, 1, 1, 1, 1, 1, 10, 10}, 2), (std::vector<std::uint32_t>{0, 7, 8}));
    EXPECT_EQ(bandsOfEqualWork({0, 0, 0, 0, 2, 6, 0, 0}, 2), (std::vector<std::uint32_t>{0, 5, 8}))
        << "the nearer of the two starts about the target";
    EXPECT_EQ(bandsOfEqualWork({0, 0, 0, 4, 1, 3, 0, 0}, 2), (std::vector<std::uint32_t>{0, 4, 8}));
    // No work at all: each band still a row.
    EXPECT_EQ(bandsOfEqualWork(std::vector<double>(4, 0.0), 4), (std::vector<std::uint32_t>{0, 1, 2, 3, 4}));
    Random rng(5);
    for (int trial = 0; trial < 200; ++trial) {
        std::vector<double> work(std::size_t(rng.uniform(1.0, 90.0)));
        for (double& v : work) v = rng.uniform() < 0.3 ? 0.0 : rng.uniform(0.0, 100.0);
        const std::size_t bands = std::size_t(rng.uniform(1.0, 9.0));
        const std::vector<std::uint32_t> starts = bandsOfEqualWork(work, bands);
        ASSERT_EQ(starts.size(), std::min(bands, work.size()) + 1);
        EXPECT_EQ(starts.front(), 0u);
        EXPECT_EQ(starts.back(), work.size());
        double total = 0.0, largestRow = 0.0;
        for (double v : work) total += v, largestRow = std::max(largestRow, v);
        for (std::size_t b = 0; b + 1 < starts.size(); ++b) {
            ASSERT_LT(starts[b], starts[b + 1]) << "every band a row at least";
            double share = 0.0;
            for (std::uint32_t r = starts[b]; r < starts[b + 1]; ++r) share += work[r];
            // Whole rows: no band's share beyond the mean by more than two rows' work at the
            // rows' own limits (each of its ends within one row of its target).
            if (starts.size() - 1 == bands)
                EXPECT_LE(share, total / double(bands) + 2.0 * largestRow + 1e-9) << "band " << b;
        }
    }
}

// The estimate follows where the triangles project and which rows' rays reach the scene; none
// without a view frustum of the frame's rows.
TEST(ImageBands, TileRowWorkFollowsTheTrianglesAndTheRays) {
    // A sphere low in the view: the rows about its image carry the work.
    Scene s = sceneFromMeshes({icosphere({0.0f, -1.2f, 0.0f}, 0.4f, 3), icosphere({0.0f, 1.3f, 0.0f}, 0.05f, 0)});
    Camera camera;
    camera.eye = glm::dvec3(0.0, 0.0, 5.0);
    camera.yfovRadians = glm::radians(40.0);
    Frame frame(std::move(s), camera, 64, 64);
    EXPECT_TRUE(tileRowWork(frame.geometry).empty()) << "no frustum";
    frame.geometry.frustum = viewFrustum(camera, 64, 64);
    const std::vector<double> work = tileRowWork(frame.geometry);
    ASSERT_EQ(work.size(), 8u);
    double top = 0.0, bottom = 0.0;
    for (std::size_t r = 0; r < 4; ++r) top += work[r], bottom += work[r + 4];
    EXPECT_GT(bottom, 3.0 * top);
    FrameGeometry otherRows = frame.geometry;
    otherRows.frustum = viewFrustum(camera, 64, 32);
    EXPECT_TRUE(tileRowWork(otherRows).empty()) << "a frustum of another image's rows";
    // The bands follow: the lower rows split among more of them.
    const std::vector<std::uint32_t> bands = imageBands(frame.geometry, 2);
    ASSERT_EQ(bands.size(), 3u);
    EXPECT_GT(bands[1], frame.rays.size() / 2);
}

// The lists made in chunks side by side are a plain filter of the traced ids by BandEdges, in
// their order: many chunks (a chunk's last writes must stay out of the next one's), up to a band
// a row of tiles (40), with and without the frame's list of traced ids; and a band start inside
// a row is refused.
TEST(ImageBands, TriangleListsAreThePlainFilterOfTheTracedIds) {
    Random rng(21);
    const Camera camera = tiltedCamera();
    const int w = 40, h = 320;
    std::vector<Triangle> tris;
    for (int i = 0; i < 70000; ++i) {
        const glm::dvec3 c = camera.eye + 6.0 * glm::dvec3(camera.forward) + 4.0 * rng.inBox(-1, 1);
        const double size = std::pow(10.0, rng.uniform(-3.0, -0.5));
        tris.push_back(doubleSided(glm::vec3(c + size * rng.inBox(-1, 1)), glm::vec3(c + size * rng.inBox(-1, 1)),
                                   glm::vec3(c + size * rng.inBox(-1, 1))));
    }
    const std::vector<Bounds> bounds = allTriangleBounds(tris);
    const std::vector<Ray> rays = primaryRays(camera, w, h);
    FrameGeometry g = frameGeometry(tris, bounds, rays, sceneBounds(tris), std::uint32_t(w));
    g.frustum = viewFrustum(camera, w, h);
    std::vector<std::uint32_t> everyThird;
    for (std::uint32_t i = 0; i < tris.size(); i += 3) everyThird.push_back(i);
    ThreadPool pool(3);
    const std::uint32_t row = std::uint32_t(w);
    for (const bool someTraced : {false, true}) {
        FrameGeometry frame = g;
        if (someTraced) frame.tracedTriangles = &everyThird;
        std::vector<std::uint32_t> everyTileRow;  // 40 bands
        for (std::uint32_t r = 0; r <= std::uint32_t(h); r += 8) everyTileRow.push_back(r * row);
        for (const std::vector<std::uint32_t>& bands : std::vector<std::vector<std::uint32_t>>{
                 {0, 160 * row, 320 * row}, {0, 8 * row, 16 * row, 24 * row, 40 * row, 48 * row, 320 * row}, everyTileRow}) {
            const std::vector<std::vector<std::uint32_t>> ids = bandTriangleIds(frame, bands, pool);
            std::vector<std::uint32_t> startRows;
            for (std::uint32_t b : bands) startRows.push_back(b / row);
            const BandEdges edges(*frame.frustum, startRows);
            ASSERT_EQ(ids.size(), bands.size() - 1);
            std::vector<std::vector<std::uint32_t>> expected(bands.size() - 1);
            for (std::size_t i = 0; i < frame.tracedTriangleCount(); ++i) {
                const auto [first, last] = edges.bandsOf(bounds[frame.tracedTriangle(i)]);
                for (std::uint32_t b = first; b <= last; ++b) expected[b].push_back(frame.tracedTriangle(i));
            }
            std::size_t dropped = 0;
            for (std::size_t b = 0; b + 1 < bands.size(); ++b) {
                EXPECT_EQ(ids[b], expected[b]) << "band " << b << " of " << bands.size() - 1 << ", traced list " << someTraced;
                dropped += frame.tracedTriangleCount() - expected[b].size();
            }
            EXPECT_GT(dropped, frame.tracedTriangleCount() / 2) << "the bands are narrower than the view";
        }
    }
    EXPECT_THROW(bandTriangleIds(g, {0, 160 * row + 1, 320 * row}, pool), InternalError);
}

// Bands of any layout, with each band's own triangles, from outside and inside the scene and
// through the pixels' corners, with and without packets, give brute force's hits bit for bit;
// and some band drops triangles.
TEST(ImageBands, WithTheirOwnTrianglesGiveBruteForcesHitsBitForBit) {
    const Scene s = shapesScene();
    ThreadPool pool(3);
    const int w = 64, h = 56;
    CameraOptions inside;
    inside.eye = glm::dvec3(0.2, 0.1, 0.3);
    inside.target = glm::dvec3(-0.3, -0.1, -0.6);
    for (const Camera& camera : {defaultCamera(s, w, h), defaultCamera(s, w, h, inside)})
        for (const glm::dvec2 offset : {glm::dvec2(0.5, 0.5), glm::dvec2(0.0, 0.0), glm::dvec2(1.0, 1.0)}) {
            SCOPED_TRACE("offset " + std::to_string(offset.x));
            const std::vector<Bounds> bounds = allTriangleBounds(s.triangles);
            const std::vector<Ray> rays = primaryRays(camera, w, h, offset);
            FrameGeometry g = frameGeometry(s.triangles, bounds, rays, sceneBounds(s.triangles), std::uint32_t(w));
            g.frustum = viewFrustum(camera, w, h);
            const TraceResult reference = traceFrame(g, Backend::Brute, 0, 2);
            ASSERT_GT(hitCount(reference.hits), rays.size() / 20);
            const std::uint32_t row = std::uint32_t(w) * 8, all = std::uint32_t(rays.size());
            std::size_t dropped = 0;
            for (const std::vector<std::uint32_t>& bands : std::vector<std::vector<std::uint32_t>>{
                     imageBands(g, 2), imageBands(g, 3), {0, row, all}, {0, 3 * row, 4 * row, 6 * row, all},
                     {0, row, 2 * row, 3 * row, 4 * row, 5 * row, 6 * row, all}}) {  // the last: a band a row of tiles
                ASSERT_GE(bands.size(), 3u);
                const std::vector<std::vector<std::uint32_t>> ids = bandTriangleIds(g, bands, pool);
                ASSERT_EQ(ids.size(), bands.size() - 1);
                for (const std::vector<std::uint32_t>& band : ids) {
                    dropped += s.triangles.size() - band.size();
                    EXPECT_TRUE(std::is_sorted(band.begin(), band.end()));
                }
                for (const bool packets : {true, false}) {
                    DacrtOptions options;
                    options.packets = packets;
                    EXPECT_TRUE(identicalHits(reference.hits, traceImageBands(g, options, pool, bands).hits))
                        << bands.size() - 1 << " bands, packets " << packets;
                }
            }
            EXPECT_GT(dropped, 0u);
            // The same after the frame's skips: the bands' ids from the traced ones.
            const TriangleSkips skips = skipTriangles(g, SkipSwitches{}, pool);
            const FrameGeometry skipped = withSkips(g, skips);
            const std::vector<std::uint32_t> bands = imageBands(skipped, 2);
            const std::vector<std::vector<std::uint32_t>> ids = bandTriangleIds(skipped, bands, pool);
            for (const std::vector<std::uint32_t>& band : ids)
                EXPECT_TRUE(std::includes(skips.traced.begin(), skips.traced.end(), band.begin(), band.end()));
            EXPECT_TRUE(identicalHits(reference.hits, traceImageBands(skipped, DacrtOptions{}, pool, bands).hits))
                << "after the skips";
        }
}
