#include "gpu/pipeline_store.hpp"

#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <vector>

#include "core/atomic_file.hpp"
#include "core/cache_files.hpp"
#include "gpu/embedded_shaders.hpp"
#include "gpu/vulkan_error.hpp"

namespace dacrt::gpu {
namespace {

constexpr char kMagic[8] = {'D', 'A', 'C', 'R', 'T', 'P', 'C', '1'};

VkPhysicalDeviceProperties propertiesOf(VkPhysicalDevice physical) {
    VkPhysicalDeviceProperties p;
    vkGetPhysicalDeviceProperties(physical, &p);
    return p;
}

std::string storeKey(const VkPhysicalDeviceProperties& p, const std::string& driver) {
    std::uint64_t h = fnv1a(&p.vendorID, sizeof(p.vendorID));
    h = fnv1a(&p.deviceID, sizeof(p.deviceID), h);
    h = fnv1a(&p.driverVersion, sizeof(p.driverVersion), h);
    h = fnv1a(p.pipelineCacheUUID, VK_UUID_SIZE, h);
    h = fnv1a(driver.data(), driver.size(), h);
    for (const auto& spirv : {dacrtKernelSpirv(), workgroupTestSpirv(), rayQuerySpirv()}) h = fnv1a(spirv.data(), spirv.size_bytes(), h);
    return hex16(h);
}

// The file: magic, the key (16 characters), the payload's size and hash, the payload. Sets
// `hash` to the payload's (checked) hash when the file is valid.
std::vector<char> readValid(const std::string& path, const std::string& key, std::uint64_t& payloadHash) {
    std::ifstream in(path, std::ios::binary);
    if (!in) return {};
    const std::vector<char> file((std::istreambuf_iterator<char>(in)), {});
    const std::size_t header = sizeof(kMagic) + 16 + 8 + 8;
    if (file.size() < header || std::memcmp(file.data(), kMagic, sizeof(kMagic)) != 0 ||
        std::memcmp(file.data() + sizeof(kMagic), key.data(), 16) != 0)
        return {};
    std::uint64_t size = 0, hash = 0;
    std::memcpy(&size, file.data() + sizeof(kMagic) + 16, 8);
    std::memcpy(&hash, file.data() + sizeof(kMagic) + 24, 8);
    if (size != file.size() - header || fnv1a(file.data() + header, size) != hash) return {};
    payloadHash = hash;
    return {file.begin() + std::ptrdiff_t(header), file.end()};
}

// The driver's own header (VkPipelineCacheHeaderVersionOne) must name this device too: a
// file copied from another machine under the same key is refused here, not by the driver.
bool headerMatches(const std::vector<char>& payload, const VkPhysicalDeviceProperties& p) {
    VkPipelineCacheHeaderVersionOne header;
    if (payload.size() < sizeof(header)) return false;
    std::memcpy(&header, payload.data(), sizeof(header));
    return header.headerSize >= sizeof(header) && header.headerSize <= payload.size() &&
           header.headerVersion == VK_PIPELINE_CACHE_HEADER_VERSION_ONE && header.vendorID == p.vendorID &&
           header.deviceID == p.deviceID && std::memcmp(header.pipelineCacheUUID, p.pipelineCacheUUID, VK_UUID_SIZE) == 0;
}

}  // namespace

PipelineStore::PipelineStore(VkPhysicalDevice physical, VkDevice device, const std::string& driver,
                             const std::string& folder)
    : device_(device) {
    const VkPhysicalDeviceProperties properties = propertiesOf(physical);
    key_ = storeKey(properties, driver);
    std::vector<char> data;
    if (!folder.empty()) {
        path_ = folder + "/vulkan-pipelines-" + key_ + ".bin";
        std::uint64_t hash = 0;
        data = readValid(path_, key_, hash);
        if (!data.empty() && !headerMatches(data, properties)) data.clear();
        loadedHash_ = data.empty() ? fnv1a(nullptr, 0) : hash;
    }
    VkPipelineCacheCreateInfo info{};
    info.sType = VK_STRUCTURE_TYPE_PIPELINE_CACHE_CREATE_INFO;
    info.initialDataSize = data.size();
    info.pInitialData = data.empty() ? nullptr : data.data();
    VK_CHECK(vkCreatePipelineCache(device_, &info, nullptr, &cache_));
    loaded_ = !data.empty();
}

PipelineStore::~PipelineStore() {
    save();
    vkDestroyPipelineCache(device_, cache_, nullptr);
}

void PipelineStore::save() const {
    if (path_.empty()) return;
    try {
        std::size_t size = 0;
        VK_CHECK(vkGetPipelineCacheData(device_, cache_, &size, nullptr));
        std::vector<char> payload(size);
        VK_CHECK(vkGetPipelineCacheData(device_, cache_, &size, payload.data()));
        payload.resize(size);
        const std::uint64_t bytes = payload.size(), hash = fnv1a(payload.data(), payload.size());
        if (hash == loadedHash_) return;  // nothing new to keep
        std::string file(kMagic, sizeof(kMagic));
        file += key_;
        file.append(reinterpret_cast<const char*>(&bytes), 8);
        file.append(reinterpret_cast<const char*>(&hash), 8);
        file.append(payload.data(), payload.size());
        std::error_code ec;
        std::filesystem::create_directories(std::filesystem::path(path_).parent_path(), ec);
        writeFileAtomically(path_, file);
    } catch (const std::exception&) {
        // The next process compiles again; nothing else depends on the file.
    }
}

}  // namespace dacrt::gpu
