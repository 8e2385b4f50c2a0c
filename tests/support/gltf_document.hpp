#pragma once
// glTF documents built by the tests: JSON with one data-URI buffer that accessors append to.
#include <algorithm>
#include <cstdint>
#include <cstring>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "support/data_uri.hpp"

namespace dacrt::test {

// A glTF document under construction: one buffer that accessors append to.
class Document {
public:
    Document() {
        doc_ = {{"asset", {{"version", "2.0"}}}, {"accessors", nlohmann::json::array()}, {"bufferViews", nlohmann::json::array()}};
    }

    // An accessor over float32 data (type SCALAR, VEC3, VEC4, MAT4).
    int floats(const std::vector<float>& values, const std::string& type) {
        const int components = type == "SCALAR" ? 1 : type == "VEC3" ? 3 : type == "VEC4" ? 4 : 16;
        return add(&values[0], values.size() * 4, 5126, values.size() / std::size_t(components), type);
    }
    int u16(const std::vector<std::uint16_t>& values, const std::string& type) {
        const std::size_t components = type == "SCALAR" ? 1 : 4;
        return add(&values[0], values.size() * 2, 5123, values.size() / components, type);
    }

    nlohmann::json& operator[](const char* key) { return doc_[key]; }

    // The document with its buffer.
    nlohmann::json finish() const {
        nlohmann::json d = doc_;
        d["buffers"] = {{{"byteLength", data_.size()}, {"uri", "data:application/octet-stream;base64," + base64(data_)}}};
        return d;
    }

private:
    int add(const void* p, std::size_t bytes, int componentType, std::size_t count, const std::string& type) {
        while (data_.size() % 4) data_.push_back(0);
        const std::size_t offset = data_.size();
        const auto* c = static_cast<const unsigned char*>(p);
        data_.insert(data_.end(), c, c + bytes);
        doc_["bufferViews"].push_back({{"buffer", 0}, {"byteOffset", offset}, {"byteLength", bytes}});
        nlohmann::json accessor = {{"bufferView", doc_["bufferViews"].size() - 1}, {"componentType", componentType}, {"count", count}, {"type", type}};
        if (type == "SCALAR" && componentType == 5126) {  // animation inputs need min and max
            float lo = 1e30f, hi = -1e30f;
            for (std::size_t i = 0; i < count; ++i) {
                float v;
                std::memcpy(&v, c + i * 4, 4);
                lo = std::min(lo, v);
                hi = std::max(hi, v);
            }
            accessor["min"] = {lo};
            accessor["max"] = {hi};
        }
        doc_["accessors"].push_back(accessor);
        return int(doc_["accessors"].size() - 1);
    }

    nlohmann::json doc_;
    std::vector<unsigned char> data_;
};

}  // namespace dacrt::test
