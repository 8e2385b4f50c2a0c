#pragma once
// The compiled pipelines (the DACRT kernel's and the ray-query shader's), kept across frames (an orbit, a benchmark), one per
// set of specialization constants: creating one costs about 40 ms on lavapipe.
#include <cstdint>
#include <map>
#include <memory>
#include <tuple>
#include <utility>
#include <vector>

#include "gpu/compute_pipeline.hpp"

namespace dacrt::gpu {

// The kernel's specialization constants (DACRT_SPEC_* in shaders/layout.h).
struct KernelSpecialization {
    std::uint32_t workgroupSize = 0;
    std::uint32_t rayLimit = 0;
    std::uint32_t triLimit = 0;
    std::uint32_t maxDepth = 0;
    std::uint32_t loopBudget = 0;
    bool sharedStart = false;
    bool anyHit = false;
    std::uint32_t leafOverSplit = 0;  // kLeafOverSplit in shaders/dacrt.comp (defaultLeafOverSplit)
    bool lockstepSubgroups = false;   // kLockstepSubgroups (dropsBarriers)
    std::uint32_t leafBalance = 0;    // kLeafBalance (kernelLeafRule)
    std::uint32_t packetFlush = 0;    // kPacketFlush: 0, or packets (kernelUsesPackets) flushed below this many
    // The addressed kernel (DACRT_ADDRESSED) rather than the one that binds every array, with
    // chunks of chunkBytes (0: every array one chunk): DacrtBindingSet::addressed, kernelChunkBytes.
    bool addressed = false;
    std::uint32_t chunkBytes = 0;
    // The kernel with its stage clocks (DACRT_STAGE_CLOCKS, GpuTuning::stageClocks).
    bool stageClocks = false;
    bool sharedSegment = false;  // kSharedSegmentSpec: any-hit rays with one tmin and tmax
    std::uint32_t tightBoxRays = 0;  // kTightBoxRays: 0, or kTightBoxRaysPerTriangle (DacrtOptions::tightBoxes)
    std::vector<std::uint32_t> values() const;  // in constant_id order
};

constexpr std::uint32_t kSecondaryWorkgroup = 64;

class PipelineCache {
public:
    explicit PipelineCache(Context& context) : context_(context) {}
    ComputePipeline& kernel(const KernelSpecialization& specialization);
    // shaders/secondary.comp: a secondary pass's rays made and binned on the device (the DACRT
    // binding set; kSecondaryWorkgroup invocations a workgroup); addressed as the kernel is.
    ComputePipeline& secondary(bool addressed = false, std::uint32_t chunkBytes = 0);
    // shaders/rayquery.comp: rays, hits, the top-level acceleration structure.
    ComputePipeline& rayQuery();
    // Whether the ray-query pipeline has run once (its caller primes it: the shader binds an
    // acceleration structure, which only a scene has).
    bool rayQueryPrimed() const { return rayQueryPrimed_; }
    void markRayQueryPrimed() { rayQueryPrimed_ = true; }

private:
    Context& context_;
    std::unique_ptr<ComputePipeline> rayQuery_;
    std::map<std::pair<bool, std::uint32_t>, std::unique_ptr<ComputePipeline>> secondary_;  // by addressed, chunkBytes
    bool rayQueryPrimed_ = false;
    // By addressed, stage clocks and specialization values.
    std::map<std::tuple<bool, bool, std::vector<std::uint32_t>>, std::unique_ptr<ComputePipeline>> pipelines_;
};

}  // namespace dacrt::gpu
