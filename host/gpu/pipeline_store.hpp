#pragma once
// The Vulkan pipeline cache, kept across processes so that a driver compiles each pipeline
// once: a file under $XDG_CACHE_HOME/dacrt named by a key of the device (vendor, device,
// driver version and pipeline-cache UUID), the driver and the embedded SPIR-V, with a header
// that is checked on load, as is the driver's own (a damaged or foreign file is ignored and
// replaced).
#include <cstdint>
#include <string>

#include <vulkan/vulkan.h>

namespace dacrt::gpu {

class PipelineStore {
public:
    // folder empty: no file (the cache lives in memory only).
    PipelineStore(VkPhysicalDevice physical, VkDevice device, const std::string& driver, const std::string& folder);
    ~PipelineStore();  // saves the cache
    PipelineStore(const PipelineStore&) = delete;
    PipelineStore& operator=(const PipelineStore&) = delete;

    VkPipelineCache cache() const { return cache_; }
    const std::string& path() const { return path_; }
    bool loaded() const { return loaded_; }  // whether the file held a valid cache for this key
    void save() const;                         // best effort: a failed save only loses the cache

private:
    VkDevice device_;
    VkPipelineCache cache_ = VK_NULL_HANDLE;
    std::string key_;
    std::string path_;
    bool loaded_ = false;
    std::uint64_t loadedHash_ = 0;  // of what the file held, so that an unchanged cache is not rewritten
};

}  // namespace dacrt::gpu
