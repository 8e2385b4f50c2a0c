// libFuzzer target (docs/fuzzing.md): the AOV reader of `dacrt compare` (readAov, OpenImageIO
// reading an OpenEXR file). The bytes are written to a file of this process's own (OpenImageIO
// reads AOVs by path, and picks the reader by the .exr extension, then by the bytes) and read
// back with a 16 MiB limit on what the header may ask for, far below libFuzzer's
// -malloc_limit_mb (and low enough that reading megapixels that are not there, under
// AddressSanitizer, does not slow the fuzzer tenfold; larger headers are refused the same way). Bad input must end in dacrt::InputError; anything else is a finding, and so
// is an AOV whose channels do not hold width x height values.
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>

#include <unistd.h>

#include "core/errors.hpp"
#include "core/image_io.hpp"
#include "fuzz_support.hpp"

namespace {

const std::string& scratchPath() {
    static const std::string path =
        (std::filesystem::temp_directory_path() / ("dacrt_exr_fuzzer_" + std::to_string(::getpid()) + ".exr")).string();
    return path;
}

void expectPixels(std::size_t size, std::size_t pixels, const char* what) {
    if (size == pixels) return;
    std::fprintf(stderr, "exr_fuzzer: %s has %zu values for %zu pixels\n", what, size, pixels);
    std::abort();
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    {
        std::ofstream out(scratchPath(), std::ios::binary | std::ios::trunc);
        out.write(reinterpret_cast<const char*>(data), std::streamsize(size));
    }
    try {
        const dacrt::Aov aov = dacrt::readAov(scratchPath(), 16ull << 20);
        const std::size_t pixels = std::size_t(aov.width) * std::size_t(aov.height);
        expectPixels(aov.depth.size(), pixels, "Z");
        expectPixels(aov.normal.size(), pixels, "N");
        expectPixels(aov.primId.size(), pixels, "primId");
        if (!aov.albedo.empty()) expectPixels(aov.albedo.size(), pixels, "albedo");
        for (const dacrt::AovChannel& c : aov.extra) expectPixels(c.values.size(), pixels, c.name.c_str());
        if (dacrt::fuzz::verbose()) std::fprintf(stderr, "read a %d x %d AOV\n", aov.width, aov.height);
    } catch (const dacrt::InputError& e) {
        if (dacrt::fuzz::verbose()) std::fprintf(stderr, "refused: %s\n", e.what());
    }
    return 0;
}
