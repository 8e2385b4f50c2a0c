// A perspective row's rays made several pixels per instruction (pixel_ray_rows.hpp) are
// PixelRays::ray's, makeRay's, bit for bit: random cameras, image sizes and pixel offsets,
// directions along the axes and on the diagonals (ties between components), and the lanes
// makeRay must handle itself; on every SIMD target this machine runs.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <limits>
#include <vector>

#include "core/camera.hpp"
#include "core/errors.hpp"
#include "core/pixel_ray_rows.hpp"
#include "core/random.hpp"
#include "cpu/simd_kernels.hpp"
#include "support/simd_targets.hpp"

namespace dacrt {
namespace {

::testing::AssertionResult sameBits(const Ray& a, const Ray& b) {
    if (std::memcmp(&a, &b, sizeof(Ray)) == 0) return ::testing::AssertionSuccess();
    return ::testing::AssertionFailure() << "dir (" << a.dir.x << ", " << a.dir.y << ", " << a.dir.z << ") axes "
                                         << a.axes << " against (" << b.dir.x << ", " << b.dir.y << ", " << b.dir.z
                                         << ") axes " << b.axes;
}

// Every row of the camera's image: rowRays makes the whole row, each ray ray(x, y)'s bits; and
// tileDirections every 4x4 tile (lanes past the image's edges too), each lane's origin and dir
// ray(x, y)'s.
void expectRowsArePixelRays(const Camera& camera, int width, int height, glm::dvec2 offset) {
    const PixelRays pixels(camera, width, height, offset);
    std::vector<Ray> row(std::size_t(width) + 1);
    for (int y = 0; y < height; ++y) {
        ASSERT_EQ(pixels.rowRays(y, 0, width, row.data()), width) << "row " << y;
        for (int x = 0; x < width; ++x) ASSERT_TRUE(sameBits(row[std::size_t(x)], pixels.ray(x, y))) << x << ", " << y;
    }
    for (int y0 = 0; y0 < height; y0 += 4)
        for (int x0 = 0; x0 < width; x0 += 4) {
            Ray tile[16];
            ASSERT_EQ(pixels.tileDirections(x0, y0, tile), 16) << "tile " << x0 << ", " << y0;
            for (int l = 0; l < 16; ++l) {
                const Ray one = pixels.ray(x0 + l % 4, y0 + l / 4);
                ASSERT_EQ(std::memcmp(&tile[l].origin, &one.origin, sizeof(one.origin)), 0) << x0 << ", " << y0 << " lane " << l;
                ASSERT_EQ(std::memcmp(&tile[l].dir, &one.dir, sizeof(one.dir)), 0) << x0 << ", " << y0 << " lane " << l;
            }
        }
}

using PixelRayRowsOnEveryTarget = test::OnEveryTarget;

Camera perspective(glm::dvec3 eye, glm::dvec3 forward, glm::dvec3 upHint, double fovDegrees) {
    Camera c;
    c.eye = eye;
    c.forward = glm::normalize(forward);
    c.up = glm::normalize(upHint - glm::dot(upHint, c.forward) * c.forward);
    c.yfovRadians = fovDegrees * M_PI / 180.0;
    return c;
}

TEST_F(PixelRayRowsOnEveryTarget, RandomCamerasGiveMakeRaysBits) {
    forEachTarget([] {
        Random random(20261205);
        for (int k = 0; k < 200; ++k) {
            const glm::dvec3 forward = glm::dvec3(random.onSphere());
            glm::dvec3 upHint = glm::dvec3(random.onSphere());
            if (std::abs(glm::dot(upHint, forward)) > 0.99) upHint = glm::dvec3(forward.y, forward.z, forward.x);
            const Camera camera = perspective(glm::dvec3(random.vec3(-100.0f, 100.0f)), forward, upHint,
                                              1.0 + 178.0 * random.uniform());
            const int width = 1 + int(random.uniform() * 70.0), height = 1 + int(random.uniform() * 9.0);
            SCOPED_TRACE("camera " + std::to_string(k));
            expectRowsArePixelRays(camera, width, height, {random.uniform(), random.uniform()});
        }
    });
}

TEST_F(PixelRayRowsOnEveryTarget, AxisAndDiagonalDirectionsGiveMakeRaysBits) {
    forEachTarget([] {
        // Centre pixels along the axes (zero components, both signs), and views whose rays have
        // equal components (makeRay's axes take the first of equals).
        for (const glm::dvec3 forward : {glm::dvec3(0, 0, -1), glm::dvec3(0, 0, 1), glm::dvec3(1, 0, 0), glm::dvec3(-1, 0, 0),
                                         glm::dvec3(1, 1, 0), glm::dvec3(-1, 1, 1), glm::dvec3(1, -1, -1)})
            for (const glm::dvec3 up : {glm::dvec3(0, 1, 0), glm::dvec3(0, 0, 1), glm::dvec3(1, 0, 0)}) {
                if (std::abs(glm::dot(glm::normalize(forward), up)) > 0.9) continue;
                for (int size : {1, 3, 17, 64})
                    expectRowsArePixelRays(perspective({0, 0, 0}, forward, up, 90.0), size, size, {0.5, 0.5});
            }
    });
}

// The lanes makeRay handles itself: a row whose directions overflow at the edges is made up to
// the first of them, and makeRay then scales what it can (a direction longer than 2^511 would
// have become zero in glm::normalize's squares) and refuses the infinite.
TEST_F(PixelRayRowsOnEveryTarget, LanesBeyondTheSquaresRangeAreLeftToMakeRay) {
    forEachTarget([] {
        PerspectivePixels row;  // row 0 of 1: sy = 0
        row.width = 8.0;
        row.halfHeight = 1e308;
        row.aspect = 10.0;  // sx = (2 (x + 0.5) / 8 - 1) 1e309: infinite for x < 3 and x > 4
        row.right = {1.0, 0.0, 0.0};
        row.forward = {0.0, 0.0, -1.0};
        row.up = {0.0, 1.0, 0.0};
        row.origin = {1.0f, 2.0f, 3.0f};
        Ray out[8];
        EXPECT_EQ(perspectiveRowRays(row, 0, 0, 8, out), 0);
        // x = 3: sx = -1.25e308, whose square overflows: left to makeRay, which scales it.
        EXPECT_EQ(perspectiveRowRays(row, 0, 3, 2, out), 0);
        const Ray scaled = makeRay(row.origin, {-1.25e308, 0.0, -1.0});
        EXPECT_EQ(scaled.dir.x, -1.0f);
        EXPECT_EQ(scaled.dir.y, 0.0f);
        EXPECT_EQ(scaled.dir.z, 0.0f);  // -1 / 1.25e308 flushed below 2^-64
        EXPECT_TRUE(sameBits(scaled, makeRay(row.origin, {-1.0, 0.0, 0.0})));
        // Squares within the range for x = 3 and 4 only (|sx| 1.25e154, then 3.75e154): those two.
        row.halfHeight = 1e154;
        ASSERT_EQ(perspectiveRowRays(row, 0, 3, 5, out), 2);
        for (int x = 3; x < 5; ++x) {
            const double sx = (2.0 * (x + 0.5) / 8.0 - 1.0) * 1e154 * 10.0;
            EXPECT_TRUE(sameBits(out[x - 3], makeRay(row.origin, {sx, 0.0, -1.0}))) << x;
        }
        // Within the range: made, the bits of makeRay.
        row.halfHeight = 1e100;
        ASSERT_EQ(perspectiveRowRays(row, 0, 0, 8, out), 8);
        for (int x = 0; x < 8; ++x) {
            const double sx = (2.0 * (x + 0.5) / 8.0 - 1.0) * 1e100 * 10.0;
            EXPECT_TRUE(sameBits(out[x], makeRay(row.origin, {sx, 0.0, -1.0}))) << x;
        }
        EXPECT_THROW(makeRay(row.origin, {-std::numeric_limits<double>::infinity(), 0.0, -1.0}), InputError);
    });
}

// makeRay normalizes any finite non-zero direction, however long or short.
TEST(PixelRayRows, MakeRayNormalizesDirectionsOfAnyExponent) {
    const Ray unit = makeRay({0, 0, 0}, {3.0, -4.0, 12.0});
    for (int exponent : {-1070, -900, -600, -520, 520, 600, 900, 1000}) {
        const glm::dvec3 d(std::ldexp(3.0, exponent), std::ldexp(-4.0, exponent), std::ldexp(12.0, exponent));
        EXPECT_TRUE(sameBits(makeRay({0, 0, 0}, d), unit)) << "2^" << exponent;
    }
    EXPECT_THROW(makeRay({0, 0, 0}, {0.0, -0.0, 0.0}), InputError);
}

// A camera whose right vector is not finite: no lane is made, and primaryRays names the fault.
TEST(PixelRayRows, ANonFiniteCameraIsRefusedWithMakeRaysMessage) {
    Camera broken;
    broken.forward = {0.0, 0.0, 0.0};
    broken.yfovRadians = 1.0;
    const PixelRays pixels(broken, 4, 2);
    Ray row[16];
    EXPECT_EQ(pixels.rowRays(0, 0, 4, row), 0);
    EXPECT_EQ(pixels.tileDirections(0, 0, row), 0);
    try {
        primaryRays(broken, 4, 2);
        FAIL() << "no error";
    } catch (const InputError& e) {
        EXPECT_NE(std::string(e.what()).find("must be finite"), std::string::npos) << e.what();
    }
}

}  // namespace
}  // namespace dacrt
