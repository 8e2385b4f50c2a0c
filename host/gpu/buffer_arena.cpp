#include "gpu/buffer_arena.hpp"

#include "core/errors.hpp"
#include "gpu/binding_set.hpp"

namespace dacrt::gpu {

namespace {

// A kept buffer serves a smaller array up to this factor: beyond it the memory it holds idle
// matters more than the allocation it saves.
constexpr std::uint64_t kLargestOverFit = 2;

bool suits(const std::shared_ptr<Buffer>& buffer, std::uint64_t keptChunkBytes, const PlannedBuffer& planned) {
    const std::uint64_t need = std::max<std::uint64_t>(planned.bytes, 16);  // as Buffer allocates it
    return keptChunkBytes == planned.chunkBytes && buffer->size() >= need && buffer->size() <= kLargestOverFit * need;
}

}  // namespace

int BufferArena::bestFit(std::uint32_t binding, const PlannedBuffer& planned) const {
    int best = -1;
    const std::vector<Kept>& kept = kept_.at(binding);
    for (std::size_t i = 0; i < kept.size(); ++i) {
        const Kept& k = kept[i];
        if (k.buffer.use_count() != 1 || !suits(k.buffer, k.chunkBytes, planned)) continue;
        if (best < 0 || k.buffer->size() < kept[std::size_t(best)].buffer->size()) best = int(i);
    }
    return best;
}

bool BufferArena::wouldReuse(std::uint32_t binding, const PlannedBuffer& planned) const {
    return bestFit(binding, planned) >= 0;
}

std::uint64_t BufferArena::reusableBytes(const DacrtBufferPlan& plan, const BoundElsewhere& elsewhere) const {
    std::uint64_t bytes = 0;
    for (std::uint32_t k = 0; k < plan.size(); ++k)
        if (!elsewhere[k] && wouldReuse(k, plan[k])) bytes += plan[k].bytes;
    return bytes;
}

void BufferArena::releaseFree(std::uint32_t binding, std::uint64_t before) {
    std::vector<Kept>& kept = kept_.at(binding);
    std::erase_if(kept, [&](const Kept& k) { return k.buffer.use_count() == 1 && k.lastFrame < before; });
}

std::shared_ptr<Buffer> BufferArena::lease(const Context& context, std::uint32_t binding, const PlannedBuffer& planned) {
    std::vector<Kept>& kept = kept_.at(binding);
    if (const int fit = bestFit(binding, planned); fit >= 0) {
        kept[std::size_t(fit)].lastFrame = frame_;
        return kept[std::size_t(fit)].buffer;
    }
    releaseFree(binding, frame_ - 1);
    std::shared_ptr<Buffer> buffer;
    try {
        buffer = std::make_shared<Buffer>(context, planned.bytes, planned.name, BufferUse::Storage, planned.chunkBytes);
    } catch (const InputError&) {  // out of device memory: what no frame holds now goes first
        for (std::uint32_t k = 0; k < kept_.size(); ++k) releaseFree(k, frame_ + 1);
        buffer = std::make_shared<Buffer>(context, planned.bytes, planned.name, BufferUse::Storage, planned.chunkBytes);
    }
    kept.push_back(Kept{buffer, planned.chunkBytes, frame_});
    return buffer;
}

std::uint64_t BufferArena::bytesKept() const {
    std::uint64_t bytes = 0;
    for (const auto& binding : kept_)
        for (const Kept& k : binding) bytes += k.buffer->size();
    return bytes;
}

}  // namespace dacrt::gpu
