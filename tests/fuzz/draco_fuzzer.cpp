// libFuzzer target (docs/fuzzing.md): a KHR_draco_mesh_compression stream. The bytes are the
// stream; the target places it in a .glb whose one primitive decodes it, with POSITION,
// NORMAL and COLOR_0 naming Draco attributes 0, 1 and 2. The accessors declare the counts the
// stream's header declares (read by the loader's own core/gltf_draco_header), so that a
// mutated stream reaches Draco's decoder rather than stopping at the count check; when the
// header is unreadable they declare one triangle. The first byte chooses whether the
// primitive names an indices accessor (bit 0) and which attributes it declares (bits 1-2).
// Bad input must end in dacrt::InputError; anything else is a finding.
#include <cstddef>
#include <cstdint>
#include <span>

#include <nlohmann/json.hpp>

#include "core/gltf_draco_header.hpp"
#include "fuzz_support.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    if (size < 1) return 0;
    const std::uint8_t choice = data[0];
    const std::span<const unsigned char> stream(data + 1, size - 1);
    const dacrt::gltf::DracoStreamCounts counts = dacrt::gltf::readDracoStreamCounts(stream);
    const bool read = counts.problem.empty();
    const std::uint64_t corners = read ? counts.faces * 3 : 3, points = read && !counts.edgebreaker ? counts.vertices : corners;
    const bool indexed = (choice & 1) != 0;

    nlohmann::json attributes = {{"POSITION", 0}}, ids = {{"POSITION", 0}};
    nlohmann::json accessors = {{{"componentType", 5126}, {"count", indexed ? points : corners}, {"type", "VEC3"}}};
    if (choice & 2) {
        accessors.push_back({{"componentType", 5126}, {"count", indexed ? points : corners}, {"type", "VEC3"}});
        attributes["NORMAL"] = accessors.size() - 1;
        ids["NORMAL"] = 1;
    }
    if (choice & 4) {
        accessors.push_back({{"componentType", 5121}, {"normalized", true}, {"count", indexed ? points : corners}, {"type", "VEC4"}});
        attributes["COLOR_0"] = accessors.size() - 1;
        ids["COLOR_0"] = 2;
    }
    nlohmann::json primitive = {{"attributes", attributes},
                                {"extensions", {{"KHR_draco_mesh_compression", {{"bufferView", 0}, {"attributes", ids}}}}}};
    if (indexed) {
        accessors.push_back({{"componentType", 5125}, {"count", corners}, {"type", "SCALAR"}});
        primitive["indices"] = accessors.size() - 1;
    }
    const nlohmann::json doc = dacrt::fuzz::onePrimitiveDocument(
        "KHR_draco_mesh_compression", true, {{{"byteLength", stream.size()}}}, {{{"buffer", 0}, {"byteLength", stream.size()}}},
        accessors, primitive);
    dacrt::fuzz::load(dacrt::fuzz::glb(doc.dump(), stream), "fuzz-draco.glb");
    return 0;
}
