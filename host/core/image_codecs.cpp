#include "core/image_codecs.hpp"

#include <dlfcn.h>

#include <cstdlib>
#include <mutex>
#include <stdexcept>

namespace dacrt {
namespace {

// Where this build put its module, and where `cmake --install` puts it (CMake defines both).
constexpr const char* kBuiltModule = DACRT_CODECS_BUILD_PATH;
constexpr const char* kInstalledModule = DACRT_CODECS_INSTALL_PATH;

// The table of the module at `path`, or null with `why` set.
const ImageCodecs* tableAt(const std::string& path, std::string& why) {
    // RTLD_LAZY: functions bound on first call, as at a program start. RTLD_LOCAL: OpenImageIO's symbols stay out of the process's global scope. The module is
    // never closed: readers it made may live until exit.
    void* module = dlopen(path.c_str(), RTLD_LAZY | RTLD_LOCAL);
    if (!module) {
        const char* error = dlerror();
        why = error ? error : "dlopen failed";
        return nullptr;
    }
    using Entry = const ImageCodecs* (*)();
    const auto entry = reinterpret_cast<Entry>(dlsym(module, DACRT_IMAGE_CODECS_ENTRY));
    if (!entry) {
        why = "no " DACRT_IMAGE_CODECS_ENTRY " in it";
        return nullptr;
    }
    const ImageCodecs* table = entry();
    if (!table || table->interface != kImageCodecsInterface || table->tableSize != sizeof(ImageCodecs)) {
        why = "it was built from another version of dacrt (interface " + std::to_string(table ? table->interface : 0) +
              ", this build needs " + std::to_string(kImageCodecsInterface) + ")";
        return nullptr;
    }
    return table;
}

const ImageCodecs* loadCodecs(std::string& failures) {
    std::vector<std::string> candidates;
    if (const char* chosen = std::getenv("DACRT_CODECS_MODULE"); chosen && *chosen)
        candidates = {chosen};  // the caller's choice alone: no silent fallback behind it
    else
        candidates = {kBuiltModule, kInstalledModule};
    for (const std::string& path : candidates) {
        std::string why;
        if (const ImageCodecs* table = tableAt(path, why)) return table;
        failures += "\n  " + path + ": " + why;
    }
    return nullptr;
}

}  // namespace

const ImageCodecs& imageCodecs() {
    static std::once_flag once;
    static const ImageCodecs* table = nullptr;
    static std::string failures;
    std::call_once(once, [] { table = loadCodecs(failures); });
    if (!table)
        throw std::runtime_error("dacrt's image codecs (libdacrt_codecs.so, OpenImageIO) could not be loaded, so this installation of dacrt cannot read or write images; tried:" +
                                 failures + "\nset DACRT_CODECS_MODULE to the module's path");
    return *table;
}

}  // namespace dacrt
