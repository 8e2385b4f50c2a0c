#pragma once
// Device buffers kept from one frame to the next for the bindings a frame fills anew (rays,
// hits, ids, work items, states): a later frame whose arrays fit reuses them instead of
// allocating its own. Host-visible memory that is freshly allocated costs its page faults at
// the first write, every frame; on the project's VM that was most of a Bunny frame's upload
// (docs/gpu.md, "Buffers kept between frames").
#include <array>
#include <cstdint>
#include <memory>
#include <vector>

#include "core/shader_layout.hpp"
#include "gpu/buffer.hpp"

namespace dacrt::gpu {

struct PlannedBuffer;
using DacrtBufferPlan = std::array<PlannedBuffer, DACRT_BINDING_COUNT>;
// The bindings whose buffers come from elsewhere (resident triangles, a primary pass's).
using BoundElsewhere = std::array<bool, DACRT_BINDING_COUNT>;

class BufferArena {
public:
    // A new frame begins (its primary pass): buffers that neither it nor the last frame leased
    // may be released to make room.
    void startFrame() { ++frame_; }
    // A buffer for `binding` of at least planned.bytes, in planned.chunkBytes chunks (0: one
    // allocation), that no one else holds now: a kept one that fits, else a new one. A frame's
    // passes of different sizes (a primary pass, a shadow pass, four occlusion rays per pixel)
    // each find their own from the last frame. Before a new one is allocated, the free buffers
    // of the binding that the last two frames did not use are released; if the device's memory
    // is still short, every free buffer is.
    std::shared_ptr<Buffer> lease(const Context& context, std::uint32_t binding, const PlannedBuffer& planned);
    // Whether lease() would reuse a kept buffer (for the memory plan, before anything is leased).
    bool wouldReuse(std::uint32_t binding, const PlannedBuffer& planned) const;
    // The bytes of a binding set's buffers (those not bound elsewhere) that lease() would reuse.
    std::uint64_t reusableBytes(const DacrtBufferPlan& plan, const BoundElsewhere& elsewhere) const;
    // Bytes of every kept buffer, leased or not.
    std::uint64_t bytesKept() const;

private:
    struct Kept {
        std::shared_ptr<Buffer> buffer;
        std::uint64_t chunkBytes = 0;  // as requested: 0 for one allocation
        std::uint64_t lastFrame = 0;   // the frame that leased it last
    };
    // Releases the free buffers of `binding` last leased before frame `before`.
    void releaseFree(std::uint32_t binding, std::uint64_t before);
    // The free kept buffer of `binding` that suits `planned` best (the smallest that fits), or -1.
    int bestFit(std::uint32_t binding, const PlannedBuffer& planned) const;
    std::array<std::vector<Kept>, DACRT_BINDING_COUNT> kept_;
    std::uint64_t frame_ = 1;
};

}  // namespace dacrt::gpu
