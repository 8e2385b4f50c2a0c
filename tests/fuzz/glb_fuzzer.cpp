// libFuzzer target (docs/fuzzing.md): the .glb container. The bytes are a .glb's chunks
// (length, type, data: JSON, BIN, and any others); the target puts the 12-byte header before
// them with the right total length, so that every mutation reaches the chunk reader and the
// accessors' ranges in the BIN chunk rather than stopping at the header's length.
// Bad input must end in dacrt::InputError; anything else is a finding.
#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

#include "fuzz_support.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    const std::vector<unsigned char> glb = dacrt::fuzz::glbWithHeader(std::span<const unsigned char>(data, size));
    dacrt::fuzz::load(glb, "fuzz.glb");
    return 0;
}
