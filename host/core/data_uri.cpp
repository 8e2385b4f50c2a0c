#include "core/data_uri.hpp"

#include <cstdint>
#include <string_view>

namespace dacrt {
namespace {

// A base64 digit's value; -1 for any other character.
int digitValue(char c) {
    if (c >= 'A' && c <= 'Z') return c - 'A';
    if (c >= 'a' && c <= 'z') return c - 'a' + 26;
    if (c >= '0' && c <= '9') return c - '0' + 52;
    if (c == '+') return 62;
    if (c == '/') return 63;
    return -1;
}

}  // namespace

std::vector<unsigned char> dataUriBytes(const std::string& uri, std::string& why) {
    constexpr std::string_view kBase64 = ";base64";
    const std::size_t comma = uri.find(',');
    const std::string_view header = std::string_view(uri).substr(0, comma);
    if (comma == std::string::npos || !header.ends_with(kBase64)) {
        why = "its data: URI is not base64 (data:MEDIATYPE;base64,DATA)";
        return {};
    }
    const std::string_view data = std::string_view(uri).substr(comma + 1);
    std::size_t padding = 0;
    while (padding < 2 && padding < data.size() && data[data.size() - 1 - padding] == '=') ++padding;
    std::vector<unsigned char> out;
    out.reserve(data.size() / 4 * 3);
    std::uint32_t bits = 0;
    for (std::size_t i = 0; i + padding < data.size(); ++i) {
        const int v = digitValue(data[i]);
        if (v < 0) {
            why = "its data: URI's base64 has '" + std::string(1, data[i]) + "' at character " + std::to_string(i);
            return {};
        }
        bits = bits << 6 | std::uint32_t(v);
        if (i % 4 == 3) {
            for (int shift : {16, 8, 0}) out.push_back((unsigned char)(bits >> shift & 0xFF));
            bits = 0;
        }
    }
    const std::size_t tail = (data.size() - padding) % 4;
    if (tail == 1 || (padding && data.size() % 4 != 0)) {  // unpadded groups are taken, as tinygltf takes them
        why = "its data: URI's base64 is " + std::to_string(data.size()) + " characters, a group of 4 cut short";
        return {};
    }
    if (tail == 2) out.push_back((unsigned char)(bits >> 4 & 0xFF));
    if (tail == 3) for (int shift : {10, 2}) out.push_back((unsigned char)(bits >> shift & 0xFF));
    if (out.empty()) why = "its data: URI holds no data";
    return out;
}

}  // namespace dacrt
