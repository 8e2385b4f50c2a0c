#include "gpu/pipeline_cache.hpp"

#include "core/shader_layout.hpp"
#include "gpu/embedded_shaders.hpp"

namespace dacrt::gpu {

std::vector<std::uint32_t> KernelSpecialization::values() const {
    std::vector<std::uint32_t> v(6);
    v[DACRT_SPEC_WORKGROUP_SIZE] = workgroupSize;
    v[DACRT_SPEC_RAY_LIMIT] = rayLimit;
    v[DACRT_SPEC_TRI_LIMIT] = triLimit;
    v[DACRT_SPEC_MAX_DEPTH] = maxDepth;
    v[DACRT_SPEC_LOOP_BUDGET] = loopBudget;
    v[DACRT_SPEC_SHARED_START] = sharedStart ? 1u : 0u;
    return v;
}

ComputePipeline& PipelineCache::kernel(const KernelSpecialization& specialization) {
    const std::vector<std::uint32_t> values = specialization.values();
    std::unique_ptr<ComputePipeline>& slot = pipelines_[values];
    if (!slot)
        slot = std::make_unique<ComputePipeline>(context_, dacrtKernelSpirv(), DACRT_BINDING_COUNT, sizeof(DacrtPush),
                                                 values, "dacrt");
    return *slot;
}

}  // namespace dacrt::gpu
