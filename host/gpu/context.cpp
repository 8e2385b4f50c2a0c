#include "gpu/context.hpp"

#include <algorithm>
#include <cstring>
#include <mutex>
#include <sstream>

#include "core/cache_files.hpp"
#include "core/errors.hpp"
#include "gpu/pipeline_store.hpp"
#include "gpu/vulkan_error.hpp"

namespace dacrt::gpu {

namespace {

std::string apiString(std::uint32_t v) {
    return std::to_string(VK_API_VERSION_MAJOR(v)) + "." + std::to_string(VK_API_VERSION_MINOR(v)) + "." +
           std::to_string(VK_API_VERSION_PATCH(v));
}

// What the rayquery backend needs of a device, checked by describeDevice and enabled by Context.
constexpr const char* kRayQueryExtensions[] = {VK_KHR_ACCELERATION_STRUCTURE_EXTENSION_NAME, VK_KHR_RAY_QUERY_EXTENSION_NAME,
                                               VK_KHR_DEFERRED_HOST_OPERATIONS_EXTENSION_NAME};

int typeRank(VkPhysicalDeviceType t) {  // the default choice: discrete, integrated, then the rest
    switch (t) {
        case VK_PHYSICAL_DEVICE_TYPE_DISCRETE_GPU: return 0;
        case VK_PHYSICAL_DEVICE_TYPE_INTEGRATED_GPU: return 1;
        case VK_PHYSICAL_DEVICE_TYPE_VIRTUAL_GPU: return 2;
        case VK_PHYSICAL_DEVICE_TYPE_CPU: return 3;
        default: return 4;
    }
}

VkInstance createInstance(bool validate) {
    VkApplicationInfo app{};
    app.sType = VK_STRUCTURE_TYPE_APPLICATION_INFO;
    app.pApplicationName = "dacrt";
    // 1.2 for buffer device addresses (the rayquery backend); the compute kernel needs 1.1.
    std::uint32_t loaderVersion = VK_API_VERSION_1_0;
    if (vkEnumerateInstanceVersion(&loaderVersion) != VK_SUCCESS) loaderVersion = VK_API_VERSION_1_0;
    app.apiVersion = loaderVersion >= VK_API_VERSION_1_2 ? VK_API_VERSION_1_2 : VK_API_VERSION_1_1;
    VkInstanceCreateInfo info{};
    info.sType = VK_STRUCTURE_TYPE_INSTANCE_CREATE_INFO;
    info.pApplicationInfo = &app;
    const char* layer = "VK_LAYER_KHRONOS_validation";
    const char* extension = VK_EXT_DEBUG_UTILS_EXTENSION_NAME;
    if (validate) {
        std::uint32_t count = 0;
        VK_CHECK(vkEnumerateInstanceLayerProperties(&count, nullptr));
        std::vector<VkLayerProperties> layers(count);
        VK_CHECK(vkEnumerateInstanceLayerProperties(&count, layers.data()));
        if (std::none_of(layers.begin(), layers.end(), [&](const VkLayerProperties& l) { return std::strcmp(l.layerName, layer) == 0; }))
            throw InputError("Vulkan validation was asked for, but the Khronos validation layer is not installed (Debian: vulkan-validationlayers)");
        info.enabledLayerCount = 1;
        info.ppEnabledLayerNames = &layer;
        info.enabledExtensionCount = 1;
        info.ppEnabledExtensionNames = &extension;
    }
    VkInstance instance = VK_NULL_HANDLE;
    const VkResult r = vkCreateInstance(&info, nullptr, &instance);
    if (r == VK_ERROR_INCOMPATIBLE_DRIVER || r == VK_ERROR_INITIALIZATION_FAILED)
        throw InputError(std::string("no Vulkan driver is installed (") + resultName(r) +
                         "); on Debian, mesa-vulkan-drivers provides lavapipe");
    VK_CHECK(r);
    return instance;
}

// Each memory heap as "N MiB", marked where device-local.
std::vector<std::string> memoryHeaps(VkPhysicalDevice d) {
    std::vector<std::string> heaps;
    VkPhysicalDeviceMemoryProperties memory;
    vkGetPhysicalDeviceMemoryProperties(d, &memory);
    for (std::uint32_t h = 0; h < memory.memoryHeapCount; ++h)
        heaps.push_back(std::to_string(memory.memoryHeaps[h].size >> 20) + " MiB" +
                        (memory.memoryHeaps[h].flags & VK_MEMORY_HEAP_DEVICE_LOCAL_BIT ? " (device-local)" : ""));
    return heaps;
}

// The largest device-local heap, else the largest heap: what the memory plan holds a frame to.
std::uint64_t deviceLocalBytes(VkPhysicalDevice d) {
    VkPhysicalDeviceMemoryProperties memory;
    vkGetPhysicalDeviceMemoryProperties(d, &memory);
    std::uint64_t local = 0, any = 0;
    for (std::uint32_t h = 0; h < memory.memoryHeapCount; ++h) {
        any = std::max<std::uint64_t>(any, memory.memoryHeaps[h].size);
        if (memory.memoryHeaps[h].flags & VK_MEMORY_HEAP_DEVICE_LOCAL_BIT)
            local = std::max<std::uint64_t>(local, memory.memoryHeaps[h].size);
    }
    return local ? local : any;
}

// Fills the feature structs of `chain` (a pNext chain) for the device.
void queryFeatures(VkPhysicalDevice d, void* chain) {
    VkPhysicalDeviceFeatures2 features{};
    features.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_FEATURES_2;
    features.pNext = chain;
    vkGetPhysicalDeviceFeatures2(d, &features);
}

// Whether the device has the bufferDeviceAddress feature (core in Vulkan 1.2).
bool hasBufferDeviceAddress(VkPhysicalDevice d, std::uint32_t apiVersion) {
    if (apiVersion < VK_API_VERSION_1_2) return false;
    VkPhysicalDeviceBufferDeviceAddressFeatures bda{};
    bda.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_BUFFER_DEVICE_ADDRESS_FEATURES;
    queryFeatures(d, &bda);
    return bda.bufferDeviceAddress == VK_TRUE;
}

std::vector<VkExtensionProperties> deviceExtensions(VkPhysicalDevice d) {
    std::uint32_t extensionCount = 0;
    VK_CHECK(vkEnumerateDeviceExtensionProperties(d, nullptr, &extensionCount, nullptr));
    std::vector<VkExtensionProperties> extensions(extensionCount);
    VK_CHECK(vkEnumerateDeviceExtensionProperties(d, nullptr, &extensionCount, extensions.data()));
    return extensions;
}

bool hasExtension(const std::vector<VkExtensionProperties>& extensions, const char* name) {
    return std::any_of(extensions.begin(), extensions.end(),
                       [&](const VkExtensionProperties& e) { return std::strcmp(e.extensionName, name) == 0; });
}

// What the device lacks of what the rayquery backend needs (Vulkan 1.2, kRayQueryExtensions
// and their features); empty when it has everything.
std::vector<std::string> rayQueryMissing(VkPhysicalDevice d, std::uint32_t apiVersion,
                                         const std::vector<VkExtensionProperties>& extensions) {
    std::vector<std::string> missing;
    if (apiVersion < VK_API_VERSION_1_2) missing.push_back("Vulkan 1.2");
    for (const char* e : kRayQueryExtensions)
        if (!hasExtension(extensions, e)) missing.push_back(e);
    if (missing.empty()) {
        VkPhysicalDeviceRayQueryFeaturesKHR rq{};
        rq.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_RAY_QUERY_FEATURES_KHR;
        VkPhysicalDeviceAccelerationStructureFeaturesKHR as{};
        as.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_ACCELERATION_STRUCTURE_FEATURES_KHR;
        as.pNext = &rq;
        VkPhysicalDeviceBufferDeviceAddressFeatures bda{};
        bda.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_BUFFER_DEVICE_ADDRESS_FEATURES;
        bda.pNext = &as;
        queryFeatures(d, &bda);
        if (!rq.rayQuery) missing.push_back("the rayQuery feature");
        if (!as.accelerationStructure) missing.push_back("the accelerationStructure feature");
        if (!bda.bufferDeviceAddress) missing.push_back("the bufferDeviceAddress feature");
    }
    return missing;
}

// Whether the device can promise full subgroups to a compute shader (it has
// VK_EXT_subgroup_size_control; this asks for the feature).
bool computeFullSubgroups(VkPhysicalDevice d) {
    VkPhysicalDeviceSubgroupSizeControlFeaturesEXT control{};
    control.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_SUBGROUP_SIZE_CONTROL_FEATURES_EXT;
    queryFeatures(d, &control);
    return control.computeFullSubgroups == VK_TRUE;
}

// Whether the device has VK_KHR_shader_clock with the shaderSubgroupClock feature (the
// kernel's stage clocks, GpuTuning::stageClocks).
bool subgroupClock(VkPhysicalDevice d, const std::vector<VkExtensionProperties>& extensions) {
    if (!hasExtension(extensions, VK_KHR_SHADER_CLOCK_EXTENSION_NAME)) return false;
    VkPhysicalDeviceShaderClockFeaturesKHR clock{};
    clock.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_SHADER_CLOCK_FEATURES_KHR;
    queryFeatures(d, &clock);
    return clock.shaderSubgroupClock == VK_TRUE;
}

DeviceInfo describeDevice(VkPhysicalDevice d, std::uint32_t index) {
    VkPhysicalDeviceDriverProperties driver{};
    driver.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_DRIVER_PROPERTIES;
    VkPhysicalDeviceSubgroupProperties subgroup{};
    subgroup.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_SUBGROUP_PROPERTIES;
    VkPhysicalDeviceMaintenance3Properties maintenance3{};
    maintenance3.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_MAINTENANCE_3_PROPERTIES;
    subgroup.pNext = &maintenance3;
    VkPhysicalDeviceProperties2 props{};
    props.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_PROPERTIES_2;
    props.pNext = &subgroup;
    VkPhysicalDeviceProperties basic;
    vkGetPhysicalDeviceProperties(d, &basic);
    const bool hasDriverProps = basic.apiVersion >= VK_API_VERSION_1_2;
    if (hasDriverProps) maintenance3.pNext = &driver;
    vkGetPhysicalDeviceProperties2(d, &props);
    const VkPhysicalDeviceLimits& l = props.properties.limits;
    DeviceInfo info;
    info.index = index;
    info.name = props.properties.deviceName;
    info.type = props.properties.deviceType;
    info.driver = hasDriverProps ? std::string(driver.driverName) + " " + driver.driverInfo
                                 : "driver version " + std::to_string(props.properties.driverVersion);
    info.apiVersion = apiString(props.properties.apiVersion);
    info.heaps = memoryHeaps(d);
    info.maxStorageBufferRange = l.maxStorageBufferRange;
    info.maxMemoryAllocationSize = maintenance3.maxMemoryAllocationSize;
    info.deviceLocalBytes = deviceLocalBytes(d);
    info.bufferDeviceAddress = hasBufferDeviceAddress(d, basic.apiVersion);
    info.maxComputeSharedMemorySize = l.maxComputeSharedMemorySize;
    info.maxComputeWorkGroupInvocations = l.maxComputeWorkGroupInvocations;
    info.maxComputeWorkGroupSizeX = l.maxComputeWorkGroupSize[0];
    info.maxComputeWorkGroupCountX = l.maxComputeWorkGroupCount[0];
    info.maxPerStageStorageBuffers = l.maxPerStageDescriptorStorageBuffers;
    info.subgroupSize = subgroup.subgroupSize;
    const VkSubgroupFeatureFlags needed =
        VK_SUBGROUP_FEATURE_BASIC_BIT | VK_SUBGROUP_FEATURE_ARITHMETIC_BIT | VK_SUBGROUP_FEATURE_SHUFFLE_BIT;
    info.subgroupOperations = (subgroup.supportedStages & VK_SHADER_STAGE_COMPUTE_BIT) &&
                              (subgroup.supportedOperations & needed) == needed;
    info.timestamps = l.timestampComputeAndGraphics && l.timestampPeriod > 0.0f;
    const std::vector<VkExtensionProperties> extensions = deviceExtensions(d);
    const bool sizeControl = hasExtension(extensions, VK_EXT_SUBGROUP_SIZE_CONTROL_EXTENSION_NAME);
    const std::vector<std::string> missing = rayQueryMissing(d, basic.apiVersion, extensions);
    info.rayQuery = missing.empty();
    for (std::size_t i = 0; i < missing.size(); ++i) info.rayQueryMissing += (i ? ", " : "") + missing[i];
    if (sizeControl) info.fullSubgroups = computeFullSubgroups(d);
    info.subgroupClock = subgroupClock(d, extensions);
    return info;
}

std::vector<VkPhysicalDevice> physicalDevices(VkInstance instance) {
    std::uint32_t count = 0;
    VK_CHECK(vkEnumeratePhysicalDevices(instance, &count, nullptr));
    std::vector<VkPhysicalDevice> devices(count);
    VK_CHECK(vkEnumeratePhysicalDevices(instance, &count, devices.data()));
    return devices;
}

}  // namespace

std::string DeviceInfo::typeName() const { return deviceTypeName(type); }

std::string DeviceInfo::describe() const {
    std::ostringstream s;
    s << index << ": " << name << " (" << typeName() << ")\n"
      << "   driver: " << driver << "\n"
      << "   Vulkan: " << apiVersion << "\n"
      << "   memory heaps:";
    for (const std::string& h : heaps) s << " " << h << ";";
    s << "\n   max storage buffer range: " << maxStorageBufferRange << " bytes\n"
      << "   max allocation size: " << maxMemoryAllocationSize << " bytes\n"
      << "   buffer device addresses: " << (bufferDeviceAddress ? "yes" : "no") << "\n"
      << "   compute shared memory: " << maxComputeSharedMemorySize << " bytes\n"
      << "   workgroup: " << maxComputeWorkGroupInvocations << " invocations, size x " << maxComputeWorkGroupSizeX
      << ", count x " << maxComputeWorkGroupCountX << "\n"
      << "   storage buffers per stage: " << maxPerStageStorageBuffers << "\n"
      << "   subgroup size: " << subgroupSize << (subgroupOperations ? " (arithmetic and shuffles in compute)" : " (no compute arithmetic or shuffles)")
      << "\n   full subgroups on request: " << (fullSubgroups ? "yes" : "no")
      << "\n   timestamps: " << (timestamps ? "yes" : "no")
      << "\n   shader clocks (--stage-clocks): " << (subgroupClock ? "yes" : "no")
      << "\n   ray query (rayquery backend): " << (rayQuery ? "yes" : "no, lacks " + rayQueryMissing) << "\n";
    return s.str();
}

std::uint32_t chooseDevice(const std::vector<DeviceInfo>& devices, const std::string& choice) {
    if (devices.empty()) throw InputError("no Vulkan device found (on Debian, mesa-vulkan-drivers provides lavapipe)");
    if (choice.empty()) {
        std::uint32_t best = 0;
        for (std::uint32_t i = 1; i < devices.size(); ++i)
            if (typeRank(devices[i].type) < typeRank(devices[best].type)) best = i;
        return best;
    }
    // A number is an index, never part of a name ("1" would match "LLVM 15").
    const bool numeric = std::all_of(choice.begin(), choice.end(), ::isdigit);
    for (std::uint32_t i = 0; i < devices.size(); ++i)
        if (numeric ? std::to_string(devices[i].index) == choice : devices[i].name.find(choice) != std::string::npos) return i;
    std::string choices;
    for (const DeviceInfo& d : devices) choices += "\n  " + std::to_string(d.index) + ": " + d.name + " (" + d.typeName() + ")";
    throw InputError("the device '" + choice + "' matches no Vulkan device; the choices are:" + choices);
}

std::vector<DeviceInfo> listDevices() {
    VkInstance instance = createInstance(false);
    std::vector<DeviceInfo> infos;
    try {
        const std::vector<VkPhysicalDevice> devices = physicalDevices(instance);
        for (std::uint32_t i = 0; i < devices.size(); ++i) infos.push_back(describeDevice(devices[i], i));
    } catch (...) {
        vkDestroyInstance(instance, nullptr);
        throw;
    }
    vkDestroyInstance(instance, nullptr);
    return infos;
}

struct Context::Messages {
    std::mutex mutex;
    std::uint32_t errors = 0;
    std::vector<std::string> text;

    // The debug messenger's callback (`user` is the Messages): counts the errors, keeps every message.
    static VKAPI_ATTR VkBool32 VKAPI_CALL record(VkDebugUtilsMessageSeverityFlagBitsEXT severity, VkDebugUtilsMessageTypeFlagsEXT,
                                                 const VkDebugUtilsMessengerCallbackDataEXT* data, void* user) {
        auto* m = static_cast<Messages*>(user);
        std::lock_guard<std::mutex> lock(m->mutex);
        const bool error = severity & VK_DEBUG_UTILS_MESSAGE_SEVERITY_ERROR_BIT_EXT;
        if (error) ++m->errors;
        m->text.push_back(std::string(error ? "error: " : "warning: ") + (data->pMessage ? data->pMessage : ""));
        return VK_FALSE;
    }
};

namespace {

// Validation's errors and warnings, passed to `callback` with `user`.
void createMessenger(VkInstance instance, PFN_vkDebugUtilsMessengerCallbackEXT callback, void* user,
                     VkDebugUtilsMessengerEXT& messenger) {
    auto create = reinterpret_cast<PFN_vkCreateDebugUtilsMessengerEXT>(
        vkGetInstanceProcAddr(instance, "vkCreateDebugUtilsMessengerEXT"));
    if (!create) throw InputError("Vulkan validation was asked for, but VK_EXT_debug_utils is unavailable");
    VkDebugUtilsMessengerCreateInfoEXT info{};
    info.sType = VK_STRUCTURE_TYPE_DEBUG_UTILS_MESSENGER_CREATE_INFO_EXT;
    info.messageSeverity = VK_DEBUG_UTILS_MESSAGE_SEVERITY_ERROR_BIT_EXT | VK_DEBUG_UTILS_MESSAGE_SEVERITY_WARNING_BIT_EXT;
    info.messageType = VK_DEBUG_UTILS_MESSAGE_TYPE_GENERAL_BIT_EXT | VK_DEBUG_UTILS_MESSAGE_TYPE_VALIDATION_BIT_EXT |
                       VK_DEBUG_UTILS_MESSAGE_TYPE_PERFORMANCE_BIT_EXT;
    info.pfnUserCallback = callback;
    info.pUserData = user;
    VK_CHECK(create(instance, &info, nullptr, &messenger));
}

// The first queue family that computes. A family without timestamps turns the device's
// (`info.timestamps`) off.
std::uint32_t computeQueueFamily(VkPhysicalDevice physical, DeviceInfo& info) {
    std::uint32_t familyCount = 0;
    vkGetPhysicalDeviceQueueFamilyProperties(physical, &familyCount, nullptr);
    std::vector<VkQueueFamilyProperties> families(familyCount);
    vkGetPhysicalDeviceQueueFamilyProperties(physical, &familyCount, families.data());
    std::uint32_t queueFamily = 0;
    bool found = false;
    for (std::uint32_t f = 0; f < familyCount && !found; ++f)
        if (families[f].queueFlags & VK_QUEUE_COMPUTE_BIT) queueFamily = f, found = true;
    if (!found) throw InputError("device '" + info.name + "' has no compute queue");
    if (families[queueFamily].timestampValidBits == 0) info.timestamps = false;
    return queueFamily;
}

// Puts a feature structure at the head of the device's pNext chain.
template <typename Feature>
void link(Feature& feature, void*& chain) {
    feature.pNext = chain;
    chain = &feature;
}

// A device extension with its feature structure linked.
template <typename Feature>
void enable(const char* extension, Feature& feature, void*& chain, std::vector<const char*>& enabled) {
    link(feature, chain);
    enabled.push_back(extension);
}

// The logical device with one queue of `queueFamily`, and the extensions and features `info`
// says the device has and dacrt uses.
void createDevice(VkPhysicalDevice physical, std::uint32_t queueFamily, const DeviceInfo& info, VkDevice& device) {
    const float priority = 1.0f;
    VkDeviceQueueCreateInfo queueInfo{};
    queueInfo.sType = VK_STRUCTURE_TYPE_DEVICE_QUEUE_CREATE_INFO;
    queueInfo.queueFamilyIndex = queueFamily;
    queueInfo.queueCount = 1;
    queueInfo.pQueuePriorities = &priority;
    VkDeviceCreateInfo deviceInfo{};
    deviceInfo.sType = VK_STRUCTURE_TYPE_DEVICE_CREATE_INFO;
    deviceInfo.queueCreateInfoCount = 1;
    deviceInfo.pQueueCreateInfos = &queueInfo;
    // The kernel's subgroups must be full (leaves shuffle triangles across all lanes):
    // requested where the device can promise it; elsewhere the workgroup size stays a
    // multiple of the subgroup size, which every driver known to us fills.
    std::vector<const char*> enabled;
    void* chain = nullptr;
    VkPhysicalDeviceSubgroupSizeControlFeaturesEXT control{};
    control.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_SUBGROUP_SIZE_CONTROL_FEATURES_EXT;
    if (info.fullSubgroups) {
        control.computeFullSubgroups = VK_TRUE;
        enable(VK_EXT_SUBGROUP_SIZE_CONTROL_EXTENSION_NAME, control, chain, enabled);
    }
    // Ray query where the device has it: the rayquery backend builds acceleration
    // structures from device addresses and traces them from a compute shader.
    VkPhysicalDeviceRayQueryFeaturesKHR rayQuery{};
    rayQuery.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_RAY_QUERY_FEATURES_KHR;
    VkPhysicalDeviceAccelerationStructureFeaturesKHR accel{};
    accel.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_ACCELERATION_STRUCTURE_FEATURES_KHR;
    VkPhysicalDeviceBufferDeviceAddressFeatures addresses{};
    addresses.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_BUFFER_DEVICE_ADDRESS_FEATURES;
    if (info.rayQuery) {
        rayQuery.rayQuery = VK_TRUE;
        accel.accelerationStructure = VK_TRUE;
        link(rayQuery, chain);
        link(accel, chain);
        for (const char* e : kRayQueryExtensions) enabled.push_back(e);
    }
    // The subgroup clock where the device has it: the kernel's stage clocks (--stage-clocks).
    VkPhysicalDeviceShaderClockFeaturesKHR clock{};
    clock.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_SHADER_CLOCK_FEATURES_KHR;
    if (info.subgroupClock) {
        clock.shaderSubgroupClock = VK_TRUE;
        enable(VK_KHR_SHADER_CLOCK_EXTENSION_NAME, clock, chain, enabled);
    }
    // Device addresses where the device has them: the acceleration structures' inputs, and the
    // gpu kernels' arrays beyond maxStorageBufferRange.
    if (info.bufferDeviceAddress || info.rayQuery) {
        addresses.bufferDeviceAddress = VK_TRUE;
        link(addresses, chain);
    }
    deviceInfo.pNext = chain;
    deviceInfo.enabledExtensionCount = std::uint32_t(enabled.size());
    deviceInfo.ppEnabledExtensionNames = enabled.data();
    VK_CHECK(vkCreateDevice(physical, &deviceInfo, nullptr, &device));
}

void createCommandPool(VkDevice device, std::uint32_t queueFamily, VkCommandPool& commandPool) {
    VkCommandPoolCreateInfo poolInfo{};
    poolInfo.sType = VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO;
    poolInfo.flags = VK_COMMAND_POOL_CREATE_RESET_COMMAND_BUFFER_BIT;
    poolInfo.queueFamilyIndex = queueFamily;
    VK_CHECK(vkCreateCommandPool(device, &poolInfo, nullptr, &commandPool));
}

}  // namespace

Context::Context(const ContextOptions& options) : messages_(std::make_unique<Messages>()) {
    instance_ = createInstance(options.validate);
    try {
        if (options.validate) createMessenger(instance_, &Messages::record, messages_.get(), messenger_);

        const std::vector<VkPhysicalDevice> devices = physicalDevices(instance_);
        std::vector<DeviceInfo> infos;
        for (std::uint32_t i = 0; i < devices.size(); ++i) infos.push_back(describeDevice(devices[i], i));
        const std::uint32_t chosen = chooseDevice(infos, options.device);
        physical_ = devices[chosen];
        info_ = infos[chosen];

        queueFamily_ = computeQueueFamily(physical_, info_);
        createDevice(physical_, queueFamily_, info_, device_);
        vkGetDeviceQueue(device_, queueFamily_, 0, &queue_);
        createCommandPool(device_, queueFamily_, commandPool_);

        VkPhysicalDeviceProperties p;
        vkGetPhysicalDeviceProperties(physical_, &p);
        timestampPeriodNs_ = p.limits.timestampPeriod;
        store_ = std::make_unique<PipelineStore>(physical_, device_, info_.driver,
                                                 options.persistentPipelines ? defaultCacheDir() : std::string());
    } catch (...) {
        destroy();
        throw;
    }
}

Context::~Context() { destroy(); }

VkPipelineCache Context::pipelineCache() const { return store_ ? store_->cache() : VK_NULL_HANDLE; }

void Context::destroy() {
    store_.reset();  // saved while the device lives
    if (commandPool_) vkDestroyCommandPool(device_, commandPool_, nullptr);
    if (device_) vkDestroyDevice(device_, nullptr);
    if (messenger_) {
        auto destroy = reinterpret_cast<PFN_vkDestroyDebugUtilsMessengerEXT>(
            vkGetInstanceProcAddr(instance_, "vkDestroyDebugUtilsMessengerEXT"));
        if (destroy) destroy(instance_, messenger_, nullptr);
    }
    if (instance_) vkDestroyInstance(instance_, nullptr);
    commandPool_ = VK_NULL_HANDLE;
    device_ = VK_NULL_HANDLE;
    messenger_ = VK_NULL_HANDLE;
    instance_ = VK_NULL_HANDLE;
}

std::uint32_t Context::memoryType(std::uint32_t typeBits, VkMemoryPropertyFlags wanted) const {
    VkPhysicalDeviceMemoryProperties memory;
    vkGetPhysicalDeviceMemoryProperties(physical_, &memory);
    for (std::uint32_t i = 0; i < memory.memoryTypeCount; ++i)
        if ((typeBits & (1u << i)) && (memory.memoryTypes[i].propertyFlags & wanted) == wanted) return i;
    return UINT32_MAX;
}

std::uint32_t Context::validationErrors() const {
    std::lock_guard<std::mutex> lock(messages_->mutex);
    return messages_->errors;
}

const std::vector<std::string>& Context::validationMessages() const { return messages_->text; }

}  // namespace dacrt::gpu
