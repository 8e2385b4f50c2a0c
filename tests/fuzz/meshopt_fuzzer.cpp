// libFuzzer target (docs/fuzzing.md): an EXT_meshopt_compression stream. The first five bytes
// choose what the view declares: mode (byte 0: ATTRIBUTES, TRIANGLES, INDICES), filter (byte 1:
// NONE, OCTAHEDRAL, QUATERNION, EXPONENTIAL), byteStride (byte 2: 4 to 256 in steps of 4 for
// ATTRIBUTES, 2 or 4 for indices) and count (bytes 3-4, little-endian); the rest is the
// compressed stream, in a .glb's BIN chunk. The decoded view is a triangle fan's POSITION
// (ATTRIBUTES of stride 12 or more) or its indices over three plain vertices (the index modes),
// so that what meshoptimizer decodes is read by the loader too (a fan takes any count). The extension's own declared sizes
// are not kept consistent: that is the loader's to check. Bad input must end in
// dacrt::InputError; anything else is a finding.
#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

#include <nlohmann/json.hpp>

#include "fuzz_support.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    if (size < 5) return 0;
    static const char* const kModes[] = {"ATTRIBUTES", "TRIANGLES", "INDICES"};
    static const char* const kFilters[] = {"NONE", "OCTAHEDRAL", "QUATERNION", "EXPONENTIAL"};
    const int mode = data[0] % 3;
    const std::uint32_t stride = mode == 0 ? (data[2] % 64 + 1) * 4u : (data[2] & 1) ? 4u : 2u;
    const std::uint32_t count = data[3] | std::uint32_t(data[4]) << 8;
    const std::span<const unsigned char> stream(data + 5, size - 5);

    // BIN: the stream, then (4-aligned) three plain vertices for the index modes.
    std::vector<unsigned char> bin(stream.begin(), stream.end());
    bin.resize((bin.size() + 3) / 4 * 4, 0);
    const std::size_t plain = bin.size();
    for (float f : {0.f, 0.f, 0.f, 1.f, 0.f, 0.f, 0.f, 1.f, 0.f}) {
        const auto* p = reinterpret_cast<const unsigned char*>(&f);
        bin.insert(bin.end(), p, p + 4);
    }
    const std::uint64_t decoded = std::uint64_t(count) * stride;
    nlohmann::json views = {
        {{"buffer", 1}, {"byteLength", decoded},
         {"extensions", {{"EXT_meshopt_compression", {{"buffer", 0}, {"byteLength", stream.size()}, {"byteStride", stride},
                                                      {"count", count}, {"mode", kModes[mode]}, {"filter", kFilters[data[1] % 4]}}}}}},
        {{"buffer", 0}, {"byteOffset", plain}, {"byteLength", 36}}};
    nlohmann::json accessors, primitive;
    if (mode == 0) {
        if (stride >= 12) views[0]["byteStride"] = stride;
        accessors = {{{"bufferView", 0}, {"componentType", 5126}, {"count", count}, {"type", "VEC3"}}};
        primitive = {{"attributes", {{"POSITION", 0}}}, {"mode", 6}};
    } else {
        accessors = {{{"bufferView", 1}, {"componentType", 5126}, {"count", 3}, {"type", "VEC3"}},
                     {{"bufferView", 0}, {"componentType", stride == 4 ? 5125 : 5123}, {"count", count}, {"type", "SCALAR"}}};
        primitive = {{"attributes", {{"POSITION", 0}}}, {"indices", 1}, {"mode", 6}};
    }
    const nlohmann::json buffers = {{{"byteLength", bin.size()}},
                                    {{"byteLength", decoded}, {"extensions", {{"EXT_meshopt_compression", {{"fallback", true}}}}}}};
    const nlohmann::json doc = dacrt::fuzz::onePrimitiveDocument("EXT_meshopt_compression", false, buffers, views, accessors, primitive);
    dacrt::fuzz::load(dacrt::fuzz::glb(doc.dump(), bin), "fuzz-meshopt.glb");
    return 0;
}
