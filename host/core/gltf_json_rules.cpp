#include "core/gltf_json_rules.hpp"

#include <array>
#include <cstdint>
#include <deque>
#include <limits>
#include <span>
#include <string_view>
#include <vector>

#include <nlohmann/json.hpp>

#include "core/errors.hpp"

namespace dacrt::gltf {
namespace {

using nlohmann::json;

enum class Kind {
    Collection,  // an array of objects
    Text,        // a string
    Index,       // an index into `target`
    Int,         // an integer tinygltf keeps in an int (enums, texCoord, byteStride)
    Size,        // an integer tinygltf keeps in a size_t (offsets, lengths, counts)
};

// A member at `path` ("[]": each element of an array; "*": each member of an object) and what
// it must be. An index's `target` is the array it indexes, from the root, or (with a leading
// '.') from the element of the path's first array: an animation channel's sampler is one of its
// animation's samplers.
struct Rule {
    std::string_view path;
    Kind kind;
    std::string_view target = {};
};

// Where a textureInfo may stand: its index names a texture.
constexpr std::array<std::string_view, 7> kTextureInfos{
    "materials[].pbrMetallicRoughness.baseColorTexture",
    "materials[].pbrMetallicRoughness.metallicRoughnessTexture",
    "materials[].normalTexture",
    "materials[].occlusionTexture",
    "materials[].emissiveTexture",
    "materials[].extensions.KHR_materials_pbrSpecularGlossiness.diffuseTexture",
    "materials[].extensions.KHR_materials_pbrSpecularGlossiness.specularGlossinessTexture",
};

const std::vector<Rule>& rules() {
    static const std::vector<Rule> all = [] {
        std::vector<Rule> r;
        for (std::string_view c : {"accessors", "animations", "buffers", "bufferViews", "cameras", "images", "materials", "meshes",
                                   "nodes", "samplers", "scenes", "skins", "textures", "extensions.KHR_lights_punctual.lights"})
            r.push_back({c, Kind::Collection});
        r.insert(r.end(), {
            {"extensionsUsed[]", Kind::Text},
            {"extensionsRequired[]", Kind::Text},
            {"scene", Kind::Index, "scenes"},
            {"scenes[].nodes[]", Kind::Index, "nodes"},
            {"nodes[].camera", Kind::Index, "cameras"},
            {"nodes[].mesh", Kind::Index, "meshes"},
            {"nodes[].skin", Kind::Index, "skins"},
            {"nodes[].children[]", Kind::Index, "nodes"},
            {"nodes[].extensions.KHR_lights_punctual.light", Kind::Index, "extensions.KHR_lights_punctual.lights"},
            {"meshes[].primitives[].indices", Kind::Index, "accessors"},
            {"meshes[].primitives[].material", Kind::Index, "materials"},
            {"meshes[].primitives[].mode", Kind::Int},
            {"meshes[].primitives[].attributes.*", Kind::Index, "accessors"},
            {"meshes[].primitives[].targets[].*", Kind::Index, "accessors"},
            {"meshes[].primitives[].extensions.KHR_draco_mesh_compression.bufferView", Kind::Index, "bufferViews"},
            {"meshes[].primitives[].extensions.KHR_draco_mesh_compression.attributes.*", Kind::Int},
            {"accessors[].bufferView", Kind::Index, "bufferViews"},
            {"accessors[].byteOffset", Kind::Size},
            {"accessors[].componentType", Kind::Int},
            {"accessors[].count", Kind::Size},
            {"accessors[].sparse.count", Kind::Size},
            {"accessors[].sparse.indices.bufferView", Kind::Index, "bufferViews"},
            {"accessors[].sparse.indices.byteOffset", Kind::Size},
            {"accessors[].sparse.indices.componentType", Kind::Int},
            {"accessors[].sparse.values.bufferView", Kind::Index, "bufferViews"},
            {"accessors[].sparse.values.byteOffset", Kind::Size},
            {"bufferViews[].buffer", Kind::Index, "buffers"},
            {"bufferViews[].byteOffset", Kind::Size},
            {"bufferViews[].byteLength", Kind::Size},
            {"bufferViews[].byteStride", Kind::Int},
            {"bufferViews[].target", Kind::Int},
            {"buffers[].byteLength", Kind::Size},
            {"images[].bufferView", Kind::Index, "bufferViews"},
            {"textures[].sampler", Kind::Index, "samplers"},
            {"textures[].source", Kind::Index, "images"},
            {"textures[].extensions.EXT_texture_webp.source", Kind::Index, "images"},
            {"textures[].extensions.KHR_texture_basisu.source", Kind::Index, "images"},
            {"textures[].extensions.MSFT_texture_dds.source", Kind::Index, "images"},
            {"samplers[].magFilter", Kind::Int},
            {"samplers[].minFilter", Kind::Int},
            {"samplers[].wrapS", Kind::Int},
            {"samplers[].wrapT", Kind::Int},
            {"skins[].inverseBindMatrices", Kind::Index, "accessors"},
            {"skins[].skeleton", Kind::Index, "nodes"},
            {"skins[].joints[]", Kind::Index, "nodes"},
            {"animations[].channels[].sampler", Kind::Index, ".samplers"},
            {"animations[].channels[].target.node", Kind::Index, "nodes"},
            {"animations[].samplers[].input", Kind::Index, "accessors"},
            {"animations[].samplers[].output", Kind::Index, "accessors"},
        });
        static std::deque<std::string> paths;  // the generated rules' paths (a deque never moves them)
        auto add = [&](std::string path, Kind kind, std::string_view target = {}) {
            r.push_back({paths.emplace_back(std::move(path)), kind, target});
        };
        // tinygltf keeps an extension's numbers in an int (2^32 + 3 would be read as 3).
        for (const char* ext : {"EXT_meshopt_compression", "KHR_meshopt_compression"}) {
            const std::string at = std::string("bufferViews[].extensions.") + ext + ".";
            add(at + "buffer", Kind::Index, "buffers");
            for (const char* member : {"byteOffset", "byteLength", "byteStride", "count"}) add(at + member, Kind::Int);
        }
        for (std::string_view info : kTextureInfos) {
            add(std::string(info) + ".index", Kind::Index, "textures");
            add(std::string(info) + ".texCoord", Kind::Int);
            add(std::string(info) + ".extensions.KHR_texture_transform.texCoord", Kind::Int);
        }
        return r;
    }();
    return all;
}

std::vector<std::string_view> tokens(std::string_view path) {
    std::vector<std::string_view> out;
    while (!path.empty()) {
        const std::size_t dot = path.find('.');
        std::string_view part = path.substr(0, dot);
        path = dot == std::string_view::npos ? std::string_view() : path.substr(dot + 1);
        const bool each = part.size() > 2 && part.substr(part.size() - 2) == "[]";
        out.push_back(each ? part.substr(0, part.size() - 2) : part);
        if (each) out.push_back("[]");
    }
    return out;
}

class JsonRuleChecker {
public:
    JsonRuleChecker(const json& doc, const std::string& name) : doc_(doc), name_(name) {}

    void check(const Rule& rule) {
        rule_ = &rule;
        const std::vector<std::string_view> t = tokens(rule.path);
        walk(doc_, t, 0, nullptr, "");
    }

private:
    [[noreturn]] void fail(const std::string& what) const { throw InputError(name_ + ": " + what); }

    // Every member `path` names below `at`, each checked by the rule; absent members are not
    // checked (the parser refuses a missing required one).
    void walk(const json& at, std::span<const std::string_view> t, std::size_t i, const json* outer, const std::string& path) {
        if (i == t.size()) return checkValue(at, outer, path);
        if (t[i] == "[]") {
            if (!at.is_array()) fail(path + " is not an array");
            for (std::size_t k = 0; k < at.size(); ++k)
                walk(at[k], t, i + 1, outer ? outer : &at[k], path + "[" + std::to_string(k) + "]");
            return;
        }
        if (!at.is_object()) fail(path + " is not an object");
        if (t[i] == "*") {
            for (const auto& [key, value] : at.items()) walk(value, t, i + 1, outer, path + "." + key);
            return;
        }
        const auto member = at.find(std::string(t[i]));
        if (member != at.end()) walk(*member, t, i + 1, outer, path.empty() ? std::string(t[i]) : path + "." + std::string(t[i]));
    }

    void checkValue(const json& v, const json* outer, const std::string& path) const {
        switch (rule_->kind) {
            case Kind::Collection:
                if (!v.is_array()) fail(path + " is not an array");
                for (std::size_t k = 0; k < v.size(); ++k)
                    if (!v[k].is_object()) fail(path + "[" + std::to_string(k) + "] is not an object");
                return;
            case Kind::Text:
                if (!v.is_string()) fail(path + " " + v.dump() + " is not a string");
                return;
            default: break;
        }
        if (!v.is_number_integer()) fail(path + " " + v.dump() + " is not an integer");
        if (!v.is_number_unsigned() && v.get<std::int64_t>() < 0) fail(path + " " + v.dump() + " is negative");
        const std::uint64_t value = v.get<std::uint64_t>();
        if (rule_->kind == Kind::Int && value > std::uint64_t(std::numeric_limits<int>::max()))
            fail(path + " " + v.dump() + " is larger than " + std::to_string(std::numeric_limits<int>::max()));
        if (rule_->kind == Kind::Index) {
            const std::size_t count = targetCount(outer);
            if (value >= count) fail(path + " " + v.dump() + " is out of range (" + std::to_string(count) + " " + noun(count) + ")");
        }
    }

    // How many elements the rule's target array has (none when absent or not an array).
    std::size_t targetCount(const json* outer) const {
        std::string_view target = rule_->target;
        const json* at = &doc_;
        if (target.front() == '.') {
            at = outer;
            target.remove_prefix(1);
        }
        for (std::string_view part : tokens(target)) {
            if (!at || !at->is_object()) return 0;
            const auto member = at->find(std::string(part));
            at = member == at->end() ? nullptr : &*member;
        }
        return at && at->is_array() ? at->size() : 0;
    }

    // The target's last name, singular for one: "3 textures", "1 texture".
    std::string noun(std::size_t count) const {
        std::string_view n = rule_->target.substr(rule_->target.rfind('.') + 1);
        if (count == 1 && n.ends_with("shes")) n.remove_suffix(2);  // meshes
        else if (count == 1 && n.back() == 's') n.remove_suffix(1);
        return std::string(n);
    }

    const json& doc_;
    const std::string& name_;
    const Rule* rule_ = nullptr;
};

}  // namespace

void checkJsonRules(const json& doc, const std::string& name) {
    if (!doc.is_object()) return;  // the parser refuses it
    JsonRuleChecker checker(doc, name);
    for (const Rule& rule : rules()) checker.check(rule);
}

}  // namespace dacrt::gltf
