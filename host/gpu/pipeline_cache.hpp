#pragma once
// The DACRT kernel's compiled pipelines, kept across frames (an orbit, a benchmark), one per
// set of specialization constants: creating one costs about 40 ms on lavapipe.
#include <cstdint>
#include <map>
#include <memory>
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
    std::vector<std::uint32_t> values() const;  // in constant_id order
};

class PipelineCache {
public:
    explicit PipelineCache(Context& context) : context_(context) {}
    ComputePipeline& kernel(const KernelSpecialization& specialization);

private:
    Context& context_;
    std::map<std::vector<std::uint32_t>, std::unique_ptr<ComputePipeline>> pipelines_;
};

}  // namespace dacrt::gpu
