// What this machine offers dacrt (listDevices), and the backends it can run.
#include <string>
#include <vector>

#include "bindings.hpp"

namespace dacrt::python {

namespace {

py::dict vulkanDeviceOf(const VulkanDevice& d) {
    using namespace py::literals;
    return py::dict("index"_a = d.index, "name"_a = d.name, "driver"_a = d.driver, "type"_a = d.type,
                    "api_version"_a = d.apiVersion, "max_storage_buffer_range"_a = d.maxStorageBufferRange,
                    "max_memory_allocation_size"_a = d.maxMemoryAllocationSize,
                    "device_local_bytes"_a = d.deviceLocalBytes, "buffer_device_address"_a = d.bufferDeviceAddress,
                    "ray_query"_a = d.rayQuery,
                    "ray_query_missing"_a = d.rayQueryMissing, "subgroup_clock"_a = d.subgroupClock);
}

py::dict devices() {
    const MachineDevices machine = [] {
        py::gil_scoped_release release;
        return listDevices();
    }();
    py::dict cpu;
    cpu["model"] = machine.cpu.model;
    cpu["simd_target"] = machine.cpu.simdTarget;
    cpu["simd_targets"] = machine.cpu.simdTargets;
    py::list vulkan;
    for (const VulkanDevice& d : machine.vulkan) vulkan.append(vulkanDeviceOf(d));
    py::dict out;
    out["cpu"] = cpu;
    out["vulkan"] = vulkan;
    out["vulkan_unavailable"] = machine.vulkanUnavailable;
    return out;
}

// The backends a Tracer can open here: the CPU ones and Embree always, gpu with a Vulkan
// device, rayquery with one that has ray queries.
std::vector<std::string> backends() {
    const MachineDevices machine = [] {
        py::gil_scoped_release release;
        return listDevices();
    }();
    bool rayQuery = false;
    for (const VulkanDevice& d : machine.vulkan) rayQuery |= d.rayQuery;
    std::vector<std::string> names;
    for (const std::string& name : backendNames()) {
        const Backend b = *backendNamed(name);
        if ((b == Backend::Gpu && machine.vulkan.empty()) || (b == Backend::RayQuery && !rayQuery)) continue;
        names.push_back(name);
    }
    return names;
}

}  // namespace

void bindDevices(py::module_& m) {
    m.def("devices", &devices,
          "The processor (model, SIMD kernels) and every Vulkan device with its limits and whether it has ray "
          "queries, as `dacrt devices` prints them; vulkan_unavailable says why none could be listed.");
    m.def("backends", &backends,
          "The backends a Tracer can open on this machine, in the command line's order: brute, cpu-seq, cpu, "
          "embree always, gpu with a Vulkan device, rayquery with one that has ray queries.");
    m.attr("BACKENDS") = backendNames();
}

}  // namespace dacrt::python
