// The buffers kept between frames: a buffer is never leased twice at once; a free one that
// fits is reused, one that is far too large is not; a frame's passes of different sizes each
// keep their own; what the last two frames did not use is released before a new allocation.
#include <memory>

#include <gtest/gtest.h>

#include "gpu/binding_set.hpp"
#include "gpu/buffer_arena.hpp"
#include "support/gpu_support.hpp"

namespace dacrt {
namespace {

gpu::PlannedBuffer planned(std::uint64_t bytes) { return gpu::PlannedBuffer{"test", bytes}; }

TEST(BufferArena, LeasesEachBufferOnceAndReusesWhatFits) {
    DACRT_REQUIRE_GPU(context);
    gpu::BufferArena arena;
    const std::uint32_t rays = DACRT_BINDING_RAYS;
    std::shared_ptr<gpu::Buffer> first = arena.lease(*context, rays, planned(4096));
    gpu::Buffer* const firstAddress = first.get();
    EXPECT_FALSE(arena.wouldReuse(rays, planned(4096)));  // held
    std::shared_ptr<gpu::Buffer> second = arena.lease(*context, rays, planned(4096));
    EXPECT_NE(second.get(), firstAddress);
    first.reset();
    EXPECT_TRUE(arena.wouldReuse(rays, planned(3000)));
    EXPECT_FALSE(arena.wouldReuse(rays, planned(1000)));  // more than twice what it needs
    EXPECT_FALSE(arena.wouldReuse(rays, planned(5000)));  // too small
    EXPECT_FALSE(arena.wouldReuse(DACRT_BINDING_HITS, planned(4096)));  // another binding's
    EXPECT_EQ(arena.lease(*context, rays, planned(3000)).get(), firstAddress);
    EXPECT_EQ(arena.bytesKept(), 2u * 4096u);
}

TEST(BufferArena, KeepsEveryPassOfAFrameAndReleasesWhatTwoFramesLeftUnused) {
    DACRT_REQUIRE_GPU(context);
    gpu::BufferArena arena;
    const std::uint32_t rays = DACRT_BINDING_RAYS;
    // A frame: the primary pass holds its buffer while a shadow pass and an occlusion pass of
    // four times the rays lease theirs in turn.
    std::shared_ptr<gpu::Buffer> primary = arena.lease(*context, rays, planned(64 << 10));
    arena.lease(*context, rays, planned(16 << 10));
    arena.lease(*context, rays, planned(256 << 10));
    primary.reset();
    EXPECT_EQ(arena.bytesKept(), (64u + 16u + 256u) << 10);
    // The next frame finds all three.
    arena.startFrame();
    primary = arena.lease(*context, rays, planned(64 << 10));
    arena.lease(*context, rays, planned(16 << 10));
    arena.lease(*context, rays, planned(256 << 10));
    primary.reset();
    EXPECT_EQ(arena.bytesKept(), (64u + 16u + 256u) << 10);
    // Two frames of a smaller image: the old buffers stay while the last frame used them, and
    // go when a new one is needed after two frames without them.
    arena.startFrame();
    arena.lease(*context, rays, planned(5 << 10));
    EXPECT_EQ(arena.bytesKept(), (64u + 16u + 256u + 5u) << 10);
    arena.startFrame();
    arena.lease(*context, rays, planned(5 << 10));  // reused: nothing allocated, nothing released
    EXPECT_EQ(arena.bytesKept(), (64u + 16u + 256u + 5u) << 10);
    arena.lease(*context, rays, planned(1 << 10));  // allocated: the three unused ones go first
    EXPECT_EQ(arena.bytesKept(), (5u + 1u) << 10);
}

}  // namespace
}  // namespace dacrt
