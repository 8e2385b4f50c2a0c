#pragma once
// glTF data URIs for the documents tests build in code: bytes as base64 (RFC 4648, padded).
#include <cstdint>
#include <span>
#include <string>
#include <string_view>

namespace dacrt::test {

inline std::string base64(std::span<const unsigned char> bytes) {
    static constexpr std::string_view digits = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    std::string out;
    for (std::size_t i = 0; i < bytes.size(); i += 3) {
        const auto byte = [&](std::size_t k) { return k < bytes.size() ? std::uint32_t(bytes[k]) : 0u; };
        const std::uint32_t n = byte(i) << 16 | byte(i + 1) << 8 | byte(i + 2);
        out += digits[n >> 18 & 63];
        out += digits[n >> 12 & 63];
        out += i + 1 < bytes.size() ? digits[n >> 6 & 63] : '=';
        out += i + 2 < bytes.size() ? digits[n & 63] : '=';
    }
    return out;
}

inline std::string base64(std::string_view bytes) {
    return base64(std::span<const unsigned char>(reinterpret_cast<const unsigned char*>(bytes.data()), bytes.size()));
}

// A buffer's `uri` holding the bytes themselves.
inline std::string dataUri(std::span<const unsigned char> bytes) {
    return "data:application/octet-stream;base64," + base64(bytes);
}

}  // namespace dacrt::test
