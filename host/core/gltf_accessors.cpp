#include "core/gltf_accessors.hpp"

#include <algorithm>
#include <cstring>
#include <type_traits>

#include "core/errors.hpp"
#include "core/mapped_memory.hpp"

namespace dacrt::gltf {

std::string str(std::uint64_t v) { return std::to_string(v); }

void AccessorReader::fail(const std::string& what) const { throw InputError(name_ + ": " + what); }

std::uint64_t AccessorReader::add(std::uint64_t a, std::uint64_t b, const std::string& what) const {
    std::uint64_t r;
    if (__builtin_add_overflow(a, b, &r)) fail(what + " overflows 64 bits (" + str(a) + " + " + str(b) + ")");
    return r;
}

std::uint64_t AccessorReader::mul(std::uint64_t a, std::uint64_t b, const std::string& what) const {
    std::uint64_t r;
    if (__builtin_mul_overflow(a, b, &r)) fail(what + " overflows 64 bits (" + str(a) + " x " + str(b) + ")");
    return r;
}

std::int64_t integerMember(const tinygltf::Value& object, const char* key, std::int64_t fallback) {
    if (!object.Has(key)) return fallback;
    const tinygltf::Value& v = object.Get(key);
    if (!v.IsNumber()) return -1;
    const double d = v.GetNumberAsDouble();
    return d >= 0.0 && d <= 9.0e15 && d == double(std::int64_t(d)) ? std::int64_t(d) : -1;
}

std::string stringMember(const tinygltf::Value& object, const char* key, const char* fallback) {
    if (!object.Has(key)) return fallback;
    const tinygltf::Value& v = object.Get(key);
    return v.IsString() ? v.Get<std::string>() : std::string("(not a string)");
}

double numberMember(const tinygltf::Value& object, const char* key, std::size_t index, double fallback) {
    if (!object.Has(key)) return fallback;
    const tinygltf::Value& v = object.Get(key);
    if (v.IsArray()) {
        if (index >= v.ArrayLen() || !v.Get(int(index)).IsNumber()) return fallback;
        return v.Get(int(index)).GetNumberAsDouble();
    }
    return v.IsNumber() ? v.GetNumberAsDouble() : fallback;
}

double readComponent(const unsigned char* p, int componentType, bool normalized) {
    switch (componentType) {
        case TINYGLTF_COMPONENT_TYPE_FLOAT: { float x; std::memcpy(&x, p, 4); return x; }
        case TINYGLTF_COMPONENT_TYPE_BYTE: { const double c = double(std::int8_t(*p)); return normalized ? std::max(c / 127.0, -1.0) : c; }
        case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE: { const double c = double(*p); return normalized ? c / 255.0 : c; }
        case TINYGLTF_COMPONENT_TYPE_SHORT: { std::int16_t x; std::memcpy(&x, p, 2); return normalized ? std::max(x / 32767.0, -1.0) : double(x); }
        case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: { std::uint16_t x; std::memcpy(&x, p, 2); return normalized ? x / 65535.0 : double(x); }
        case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT: { std::uint32_t x; std::memcpy(&x, p, 4); return normalized ? x / 4294967295.0 : double(x); }
        default: return 0.0;
    }
}

const tinygltf::Accessor& AccessorReader::accessor(int index, std::initializer_list<int> types, const std::string& where) const {
    if (index < 0 || std::size_t(index) >= model_.accessors.size())
        fail(where + ": accessor " + std::to_string(index) + " does not exist");
    const tinygltf::Accessor& acc = model_.accessors[std::size_t(index)];
    if (std::find(types.begin(), types.end(), acc.type) == types.end())
        fail(where + ": accessor " + std::to_string(index) + " has the wrong type");
    return acc;
}

std::span<const unsigned char> AccessorReader::viewBytes(int view, const std::string& where) const {
    const std::string b = "buffer view " + std::to_string(view);
    if (view < 0 || std::size_t(view) >= model_.bufferViews.size()) fail(where + ": " + b + " does not exist");
    const tinygltf::BufferView& bv = model_.bufferViews[std::size_t(view)];
    if (auto d = decodedViews_.find(view); d != decodedViews_.end()) {
        if (d->second.size() < bv.byteLength)
            fail(b + ": EXT_meshopt_compression decoded " + str(d->second.size()) + " bytes, fewer than its byteLength " +
                 str(bv.byteLength));
        return {d->second.data(), bv.byteLength};
    }
    if (bv.buffer < 0 || std::size_t(bv.buffer) >= model_.buffers.size()) fail(b + " names a missing buffer");
    if (std::size_t(bv.buffer) < rewrites_.bufferIsPlaceholder.size() && rewrites_.bufferIsPlaceholder[std::size_t(bv.buffer)])
        fail(b + " lies in buffer " + std::to_string(bv.buffer) +
             ", which has no data (an EXT_meshopt_compression fallback) and is not decoded by the extension");
    const std::uint64_t bufferBytes = model_.buffers[std::size_t(bv.buffer)].data.size();
    const std::uint64_t viewEnd = add(bv.byteOffset, bv.byteLength, b + ": byteOffset + byteLength");
    if (viewEnd > bufferBytes)
        fail(b + " (byteOffset " + str(bv.byteOffset) + ", byteLength " + str(bv.byteLength) + ") runs past the end of buffer " +
             std::to_string(bv.buffer) + " (" + str(bufferBytes) + " bytes)");
    return {model_.buffers[std::size_t(bv.buffer)].data.data() + bv.byteOffset, bv.byteLength};
}

AccessorReader::Elements AccessorReader::elements(int index, std::initializer_list<int> types, const std::string& where) const {
    const tinygltf::Accessor& acc = accessor(index, types, where);
    const std::string a = where + ": accessor " + std::to_string(index);
    const int componentSize = tinygltf::GetComponentSizeInBytes(std::uint32_t(acc.componentType));
    const int components = tinygltf::GetNumComponentsInType(std::uint32_t(acc.type));
    if (componentSize <= 0 || components <= 0) fail(a + " has an unknown component type");
    if (acc.count == 0) fail(a + " has count 0 (the minimum is 1)");
    Elements e;
    e.count = acc.count;
    e.componentType = acc.componentType;
    e.components = components;
    e.normalized = acc.normalized;
    const std::uint64_t elementSize = std::uint64_t(componentSize) * std::uint64_t(components);
    e.stride = elementSize;
    if (hasNoView(index)) return e;  // zeros, before any sparse substitution

    const std::span<const unsigned char> bytes = viewBytes(acc.bufferView, a);
    const tinygltf::BufferView& bv = model_.bufferViews[std::size_t(acc.bufferView)];
    const std::string b = "buffer view " + std::to_string(acc.bufferView);
    if (bv.byteStride != 0 && (bv.byteStride < 4 || bv.byteStride > 252 || bv.byteStride % 4 != 0))
        fail(b + ": byteStride " + str(bv.byteStride) + " is not a multiple of 4 in 4..252");
    if (bv.byteStride != 0 && bv.byteStride < elementSize)
        fail(b + ": byteStride " + str(bv.byteStride) + " is smaller than the " + str(elementSize) + "-byte elements of " +
             "accessor " + std::to_string(index));
    if (acc.byteOffset % std::uint64_t(componentSize) != 0 ||
        (isDecodedView(acc.bufferView) ? 0 : add(bv.byteOffset, acc.byteOffset, a + ": offset")) % std::uint64_t(componentSize) != 0)
        fail(a + ": byteOffset " + str(acc.byteOffset) + " is not aligned to its " + std::to_string(componentSize) + "-byte components");
    e.stride = bv.byteStride ? bv.byteStride : elementSize;
    const std::uint64_t span = add(mul(acc.count - 1, e.stride, a + ": count x stride"), elementSize, a + ": size");
    const std::uint64_t end = add(acc.byteOffset, span, a + ": byteOffset + size");
    if (end > bytes.size())
        fail(a + " (" + str(acc.count) + " elements of " + str(elementSize) + " bytes, stride " + str(e.stride) +
             ", byteOffset " + str(acc.byteOffset) + ", " + str(end) + " bytes) runs past the end of " + b + " (" +
             str(bytes.size()) + " bytes)");
    e.data = bytes.data() + acc.byteOffset;
    return e;
}

void AccessorReader::applySparse(const tinygltf::Accessor& acc, const Elements& e, const std::string& where,
                                 std::vector<glm::dvec4>& out) const {
    const auto& sparse = acc.sparse;
    const std::string s = where + ": the sparse part";
    if (sparse.count <= 0 || std::uint64_t(sparse.count) > e.count)
        fail(s + " has count " + std::to_string(sparse.count) + ", not in 1.." + str(e.count));
    const int indexType = sparse.indices.componentType;
    const int indexSize = tinygltf::GetComponentSizeInBytes(std::uint32_t(indexType));
    if (indexType != TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE && indexType != TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT &&
        indexType != TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT)
        fail(s + ": indices must be unsigned 8, 16 or 32-bit integers");
    const std::uint64_t n = std::uint64_t(sparse.count);
    const std::uint64_t elementSize = std::uint64_t(tinygltf::GetComponentSizeInBytes(std::uint32_t(e.componentType))) *
                                      std::uint64_t(e.components);
    auto range = [&](int view, int offset, std::uint64_t size, const char* what) {
        const std::span<const unsigned char> bytes = viewBytes(view, s);
        if (offset < 0) fail(s + ": " + what + " byteOffset is negative");
        const std::uint64_t end = add(std::uint64_t(offset), mul(n, size, s + " size"), s + " end");
        if (end > bytes.size())
            fail(s + ": its " + what + " (" + str(n) + " of " + str(size) + " bytes at byteOffset " + std::to_string(offset) +
                 ") run past the end of buffer view " + std::to_string(view) + " (" + str(bytes.size()) + " bytes)");
        return bytes.data() + offset;
    };
    const unsigned char* indices = range(sparse.indices.bufferView, sparse.indices.byteOffset, std::uint64_t(indexSize), "indices");
    const unsigned char* values = range(sparse.values.bufferView, sparse.values.byteOffset, elementSize, "values");
    const std::uint64_t componentSize = elementSize / std::uint64_t(e.components);
    std::uint64_t previous = 0;
    for (std::uint64_t k = 0; k < n; ++k) {
        const std::uint64_t i = std::uint64_t(readComponent(indices + k * std::uint64_t(indexSize), indexType, false));
        if (i >= e.count) fail(s + ": index " + str(i) + " is out of range for " + str(e.count) + " elements");
        if (k > 0 && i <= previous) fail(s + ": indices must strictly increase (" + str(i) + " after " + str(previous) + ")");
        previous = i;
        glm::dvec4 v(0.0);
        for (int c = 0; c < e.components && c < 4; ++c)
            v[c] = readComponent(values + k * elementSize + std::uint64_t(c) * componentSize, e.componentType, e.normalized);
        out[i] = v;
    }
}

std::uint64_t AccessorReader::totalWith(std::uint64_t count, std::uint64_t elementBytes, const std::string& what) const {
    const std::uint64_t bytes = mul(count, elementBytes, what + " size");
    const std::uint64_t total = add(decodedBytes_, bytes, what + " size");
    if (byteLimit_ && total > byteLimit_)
        fail(what + " has " + str(count) + " elements, which need " + str(bytes) + " bytes to read" +
             (decodedBytes_ ? " (" + str(total) + " with the accessors read before it)" : std::string()) + ", more than the " +
             str(byteLimit_) + "-byte limit (over by " + str(total - byteLimit_) + ")");
    return total;
}

void AccessorReader::reserveDecoded(std::uint64_t count, std::uint64_t elementBytes, const std::string& what) const {
    decodedBytes_ = totalWith(count, elementBytes, what);
}

void AccessorReader::fitsDecoded(std::uint64_t count, std::uint64_t elementBytes, const std::string& what) const {
    totalWith(count, elementBytes, what);
}

bool AccessorReader::tryReserve(std::uint64_t bytes) const {
    std::uint64_t total = 0;
    if (__builtin_add_overflow(decodedBytes_, bytes, &total) || (byteLimit_ && total > byteLimit_)) return false;
    decodedBytes_ = total;
    return true;
}

std::vector<glm::dvec4> AccessorReader::readVectors(int index, std::initializer_list<int> types, const std::string& where) const {
    const Elements e = elements(index, types, where);
    reserveDecoded(e.count, sizeof(glm::dvec4), where + ": accessor " + std::to_string(index));
    // Zeros where an element has fewer than four components: glm's vectors value-initialize to 0.
    static_assert(std::is_trivially_default_constructible_v<glm::dvec4>);
    std::vector<glm::dvec4> out = mappedArray<glm::dvec4>(std::size_t(e.count));
    if (e.data) {
        const std::uint64_t componentSize = std::uint64_t(tinygltf::GetComponentSizeInBytes(std::uint32_t(e.componentType)));
        for (std::uint64_t i = 0; i < e.count; ++i) {
            const unsigned char* p = e.data + i * e.stride;
            for (int c = 0; c < e.components && c < 4; ++c)
                out[i][c] = readComponent(p + std::uint64_t(c) * componentSize, e.componentType, e.normalized);
        }
    }
    const tinygltf::Accessor& acc = model_.accessors[std::size_t(index)];
    if (acc.sparse.isSparse) applySparse(acc, e, where + ": accessor " + std::to_string(index), out);
    return out;
}

std::vector<glm::dmat4> AccessorReader::readMatrices(int index, const std::string& where) const {
    const Elements e = elements(index, {TINYGLTF_TYPE_MAT4}, where);
    const std::string a = where + ": accessor " + std::to_string(index);
    if (e.componentType != TINYGLTF_COMPONENT_TYPE_FLOAT) fail(a + ": matrices must be float32");
    if (model_.accessors[std::size_t(index)].sparse.isSparse) fail(a + ": sparse matrices are not read");
    reserveDecoded(e.count, sizeof(glm::dmat4), a);
    std::vector<glm::dmat4> out(e.count, glm::dmat4(0.0));
    for (std::uint64_t i = 0; e.data && i < e.count; ++i)
        for (int c = 0; c < 16; ++c)
            out[i][c / 4][c % 4] = readComponent(e.data + i * e.stride + std::uint64_t(c) * 4, e.componentType, false);
    return out;
}

std::vector<std::uint32_t> AccessorReader::readIndices(int index, const std::string& where) const {
    const tinygltf::Accessor& acc = accessor(index, {TINYGLTF_TYPE_SCALAR}, where);
    if (acc.componentType != TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE && acc.componentType != TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT &&
        acc.componentType != TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT)
        fail(where + ": indices must be unsigned 8, 16 or 32-bit integers");
    if (acc.normalized) fail(where + ": indices must not be normalized");
    if (acc.sparse.isSparse || hasNoView(index)) {
        const std::vector<glm::dvec4> values = readVectors(index, {TINYGLTF_TYPE_SCALAR}, where);
        std::vector<std::uint32_t> out(values.size());
        for (std::size_t i = 0; i < values.size(); ++i) out[i] = std::uint32_t(values[i].x);
        return out;
    }
    const Elements e = elements(index, {TINYGLTF_TYPE_SCALAR}, where);
    reserveDecoded(e.count, sizeof(std::uint32_t), where + ": accessor " + std::to_string(index));
    std::vector<std::uint32_t> out = mappedArray<std::uint32_t>(std::size_t(e.count));
    for (std::uint64_t i = 0; i < e.count; ++i)
        out[i] = std::uint32_t(readComponent(e.data + i * e.stride, e.componentType, false));
    return out;
}

}  // namespace dacrt::gltf
