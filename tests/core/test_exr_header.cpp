// AOV files whose OpenEXR header declares attribute sizes past the file's end are refused
// before OpenEXR reads them (core/exr_header.cpp): OpenEXR 3.1 allocates the declared size of
// a string attribute and reads it a byte at a time (the exr fuzzer's finding: 386 bytes that
// took 18 s and 2 GB to refuse).
#include <chrono>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "core/errors.hpp"
#include "core/image_io.hpp"

using namespace dacrt;

namespace {

void put32(std::string& out, std::uint32_t v) {
    for (int i = 0; i < 4; ++i) out.push_back(static_cast<char>(v >> (8 * i)));
}

// An OpenEXR header: magic, version 2 (with `flags`), then each attribute as name, type, size
// and `value` bytes, and the end of the header; then `tail` bytes.
std::string exr(std::uint32_t flags, std::int32_t declared, const std::string& value, std::size_t tail = 64) {
    std::string s;
    put32(s, 20000630);
    put32(s, 2 | flags);
    s += std::string("capDate") + '\0' + "string" + '\0';
    put32(s, std::uint32_t(declared));
    s += value;
    s += '\0';
    if (flags & 0x1000) s += '\0';  // a multi-part file's empty last header
    return s + std::string(tail, '\0');
}

std::string refusal(const std::string& bytes) {
    const std::string path = (std::filesystem::temp_directory_path() / ("dacrt_exr_header_test_" + std::to_string(::testing::UnitTest::GetInstance()->random_seed()) + ".exr")).string();
    std::ofstream(path, std::ios::binary).write(bytes.data(), std::streamsize(bytes.size()));
    std::string message = "(read)";
    try {
        readAov(path);
    } catch (const InputError& e) {
        message = e.what();
    }
    std::filesystem::remove(path);
    return message;
}

}  // namespace

TEST(ExrHeader, AttributeSizesPastTheFileAreRefusedBeforeOpenExrReadsThem) {
    const auto start = std::chrono::steady_clock::now();
    const std::string message = refusal(exr(0, 2003788819, "abc"));
    EXPECT_NE(message.find("not a readable OpenEXR header: attribute capDate (string) declares 2003788819 bytes, 68 are left in the file"),
              std::string::npos)
        << message;
    EXPECT_LT(std::chrono::steady_clock::now() - start, std::chrono::seconds(2));
    EXPECT_NE(refusal(exr(0x1000, 1000, "abc")).find("declares 1000 bytes"), std::string::npos);
    EXPECT_NE(refusal(exr(0, -5, "")).find("declares -5 bytes"), std::string::npos);
    EXPECT_NE(refusal(exr(0, 3, "abc", 0).substr(0, 20)).find("it ends inside the type of attribute capDate"), std::string::npos);
    EXPECT_NE(refusal(std::string("\x76\x2f\x31\x01\x02\x00\x00\x00", 8) + std::string(40, 'x')).find("is longer than 31 bytes"),
              std::string::npos);
    // A header that holds what it declares gets past this check to OpenEXR, which finds no
    // channels or pixels in it.
    const std::string read = refusal(exr(0, 3, "abc"));
    EXPECT_EQ(read.find("not a readable OpenEXR header"), std::string::npos) << read;
}
