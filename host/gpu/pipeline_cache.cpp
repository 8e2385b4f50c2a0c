#include "gpu/pipeline_cache.hpp"

#include "core/errors.hpp"
#include "core/shader_layout.hpp"
#include "gpu/binding_set.hpp"
#include "gpu/dispatch_recorder.hpp"
#include "gpu/embedded_shaders.hpp"

namespace dacrt::gpu {

std::vector<std::uint32_t> KernelSpecialization::values() const {
    std::vector<std::uint32_t> v(DACRT_SPEC_COUNT);
    v[DACRT_SPEC_WORKGROUP_SIZE] = workgroupSize;
    v[DACRT_SPEC_RAY_LIMIT] = rayLimit;
    v[DACRT_SPEC_TRI_LIMIT] = triLimit;
    v[DACRT_SPEC_MAX_DEPTH] = maxDepth;
    v[DACRT_SPEC_LOOP_BUDGET] = loopBudget;
    v[DACRT_SPEC_SHARED_START] = sharedStart ? 1u : 0u;
    v[DACRT_SPEC_ANY_HIT] = anyHit ? 1u : 0u;
    v[DACRT_SPEC_CHUNK_BYTES] = chunkBytes;
    v[DACRT_SPEC_LEAF_OVER_SPLIT] = leafOverSplit;
    v[DACRT_SPEC_LOCKSTEP_SUBGROUPS] = lockstepSubgroups ? 1u : 0u;
    v[DACRT_SPEC_LEAF_BALANCE] = leafBalance;
    v[DACRT_SPEC_PACKET_FLUSH] = packetFlush;
    v[DACRT_SPEC_SHARED_SEGMENT] = sharedSegment ? 1u : 0u;
    v[DACRT_SPEC_TIGHT_BOX_RAYS] = tightBoxRays;
    return v;
}

namespace {

// One of everything: the buffers a pipeline's first, empty dispatch binds.
DacrtBufferPlan primingPlan(bool addressed) {
    DacrtBufferPlan plan = planDacrtBuffers(DacrtBufferCounts{
        .rays = 1, .triangles = 1, .rayIds = 1, .triangleIds = 1, .regions = 1, .workItems = 1, .maxDepth = 0});
    if (addressed) chunkAddressedArrays(plan, DACRT_CHUNK_ALIGNMENT);
    return plan;
}

// Runs the kernel once over a work item that is already finished, so that a driver that
// compiles at the first dispatch (lavapipe does: about 10 s for this kernel on Mesa 25.0.7
// without its shader cache) does so here, where the time is reported as the pipeline's, and
// not inside a frame's dispatches.
void prime(Context& context, ComputePipeline& pipeline, bool addressed) {
    DacrtBindingSet set(context, primingPlan(addressed));
    TraversalState finished{};
    finished.phase = 2;  // kPhaseFinished in shaders/dacrt.comp
    set[DACRT_BINDING_STATES].upload(&finished, sizeof(finished));
    const WorkItem item{};
    set[DACRT_BINDING_WORK_ITEMS].upload(&item, sizeof(item));
    set.bindTo(pipeline);
    DispatchRecorder recorder(context, 1);
    const DacrtPush push{};
    recorder.dispatch("prime", pipeline, 1, &push);
    recorder.submitAndWait();
}

}  // namespace

ComputePipeline& PipelineCache::kernel(const KernelSpecialization& specialization) {
    const std::vector<std::uint32_t> values = specialization.values();
    const bool addressed = specialization.addressed, clocks = specialization.stageClocks;
    std::unique_ptr<ComputePipeline>& slot = pipelines_[{addressed, clocks, values}];
    if (!slot) {
        if (addressed && clocks) throw InternalError("the addressed kernel has no stage clocks (the tracer refuses the pair)");
        const std::span<const std::uint32_t> spirv =
            addressed ? dacrtKernelAddressedSpirv() : (clocks ? dacrtKernelClocksSpirv() : dacrtKernelSpirv());
        slot = std::make_unique<ComputePipeline>(context_, spirv, DACRT_BINDING_COUNT, sizeof(DacrtPush), values,
                                                 addressed ? "dacrt (addressed)" : (clocks ? "dacrt (stage clocks)" : "dacrt"));
        prime(context_, *slot, addressed);
    }
    return *slot;
}

ComputePipeline& PipelineCache::secondary(bool addressed, std::uint32_t chunkBytes) {
    std::unique_ptr<ComputePipeline>& slot = secondary_[{addressed, chunkBytes}];
    if (!slot) {
        std::vector<std::uint32_t> values(DACRT_SPEC_COUNT, 0);
        values[DACRT_SPEC_WORKGROUP_SIZE] = kSecondaryWorkgroup;
        values[DACRT_SPEC_MAX_DEPTH] = 1;  // the kernel has no traversal stack to size
        values[DACRT_SPEC_CHUNK_BYTES] = chunkBytes;
        slot = std::make_unique<ComputePipeline>(context_, addressed ? secondaryAddressedSpirv() : secondarySpirv(),
                                                 DACRT_BINDING_COUNT, sizeof(SecondaryPush), values, "secondary");
        // As prime() does for the kernel: a step that does nothing, so that lavapipe compiles now.
        DacrtBindingSet set(context_, primingPlan(addressed));
        set.bindTo(*slot);
        DispatchRecorder recorder(context_, 1);
        SecondaryPush push{};
        push.step = 3;  // none of shaders/secondary.comp's steps
        recorder.dispatch("prime", *slot, 1, &push);
        recorder.submitAndWait();
    }
    return *slot;
}

ComputePipeline& PipelineCache::rayQuery() {
    if (!rayQuery_)
        rayQuery_ = std::make_unique<ComputePipeline>(
            context_, rayQuerySpirv(),
            std::vector<VkDescriptorType>{VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER,
                                          VK_DESCRIPTOR_TYPE_ACCELERATION_STRUCTURE_KHR, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER},
            4 * sizeof(std::uint32_t), std::vector<std::uint32_t>{}, "rayquery");
    return *rayQuery_;
}

}  // namespace dacrt::gpu
