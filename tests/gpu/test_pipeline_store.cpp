// The pipeline cache kept across processes: what one process saves, the next loads; a file
// that is damaged, made under another key or for another device is ignored and replaced,
// never handed to the driver as it is.
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "core/cache_files.hpp"
#include "gpu/pipeline_store.hpp"
#include "support/gpu_support.hpp"

namespace dacrt {
namespace {

// The file's layout (pipeline_store.cpp): magic (8), key (16), payload size (8), payload
// hash (8), then the driver's payload, which starts with VkPipelineCacheHeaderVersionOne.
constexpr std::size_t kHeaderBytes = 40;

std::vector<char> readAll(const std::string& path) {
    std::ifstream in(path, std::ios::binary);
    return {std::istreambuf_iterator<char>(in), {}};
}

void writeAll(const std::string& path, const std::vector<char>& bytes) {
    std::ofstream(path, std::ios::binary | std::ios::trunc).write(bytes.data(), std::streamsize(bytes.size()));
}

// Rewrites the payload's hash so that only the driver's header check can refuse the file.
void rehash(std::vector<char>& file) {
    const std::uint64_t hash = fnv1a(file.data() + kHeaderBytes, file.size() - kHeaderBytes);
    std::memcpy(file.data() + 32, &hash, 8);
}

class PipelineStoreFile : public ::testing::Test {
protected:
    void SetUp() override {
        folder_ = ::testing::TempDir() + "/dacrt_pipeline_store_" +
                  ::testing::UnitTest::GetInstance()->current_test_info()->name();
        std::filesystem::remove_all(folder_);
        std::filesystem::create_directories(folder_);
    }
    void TearDown() override { std::filesystem::remove_all(folder_); }

    // A process's worth: open, (the driver fills it as pipelines are made), save on close.
    bool openAndClose(gpu::Context& context, std::string* path = nullptr) {
        gpu::PipelineStore store(context.physicalDevice(), context.device(), context.info().driver, folder_);
        if (path) *path = store.path();
        return store.loaded();
    }

    std::string folder_;
};

TEST_F(PipelineStoreFile, WhatOneProcessSavesTheNextLoads) {
    DACRT_REQUIRE_GPU(context);
    std::string path;
    EXPECT_FALSE(openAndClose(*context, &path)) << "an empty folder held a cache";
    ASSERT_TRUE(std::filesystem::exists(path)) << path;
    EXPECT_EQ(path.rfind(folder_ + "/vulkan-pipelines-", 0), 0u) << path;
    EXPECT_GE(readAll(path).size(), kHeaderBytes + sizeof(VkPipelineCacheHeaderVersionOne));
    EXPECT_TRUE(openAndClose(*context));
    EXPECT_TRUE(test::noValidationErrors(*context));
}

TEST_F(PipelineStoreFile, ADamagedFileIsIgnoredAndReplaced) {
    DACRT_REQUIRE_GPU(context);
    std::string path;
    openAndClose(*context, &path);
    std::vector<char> file = readAll(path);
    ASSERT_GT(file.size(), kHeaderBytes);
    file.back() ^= 0x5a;  // the payload no longer matches its hash
    writeAll(path, file);
    EXPECT_FALSE(openAndClose(*context));
    EXPECT_TRUE(openAndClose(*context)) << "the damaged file was not replaced";

    file = readAll(path);
    file.resize(kHeaderBytes - 1);  // truncated inside the header
    writeAll(path, file);
    EXPECT_FALSE(openAndClose(*context));
    EXPECT_TRUE(test::noValidationErrors(*context));
}

TEST_F(PipelineStoreFile, AFileOfAnotherKeyIsIgnored) {
    DACRT_REQUIRE_GPU(context);
    std::string path;
    openAndClose(*context, &path);
    std::vector<char> file = readAll(path);
    file[8] = file[8] == '0' ? '1' : '0';  // the key inside no longer matches the name's
    writeAll(path, file);
    EXPECT_FALSE(openAndClose(*context));
}

TEST_F(PipelineStoreFile, APayloadForAnotherDeviceIsNotHandedToTheDriver) {
    DACRT_REQUIRE_GPU(context);
    std::string path;
    openAndClose(*context, &path);
    std::vector<char> file = readAll(path);
    ASSERT_GE(file.size(), kHeaderBytes + sizeof(VkPipelineCacheHeaderVersionOne));
    VkPipelineCacheHeaderVersionOne header;
    std::memcpy(&header, file.data() + kHeaderBytes, sizeof(header));
    header.vendorID ^= 1u;  // as a file copied from another vendor's machine would say
    std::memcpy(file.data() + kHeaderBytes, &header, sizeof(header));
    rehash(file);
    writeAll(path, file);
    EXPECT_FALSE(openAndClose(*context));

    std::memcpy(&header, readAll(path).data() + kHeaderBytes, sizeof(header));
    header.pipelineCacheUUID[0] ^= 1u;
    file = readAll(path);
    std::memcpy(file.data() + kHeaderBytes, &header, sizeof(header));
    rehash(file);
    writeAll(path, file);
    EXPECT_FALSE(openAndClose(*context));
    EXPECT_TRUE(test::noValidationErrors(*context));
}

}  // namespace
}  // namespace dacrt
