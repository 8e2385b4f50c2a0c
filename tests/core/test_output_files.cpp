// Outputs written all or none, and inputs read only from regular files (core/atomic_file.hpp,
// core/output_target.hpp, core/input_file.hpp).
#include <csignal>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <thread>

#include <gtest/gtest.h>
#include <sys/resource.h>
#include <sys/stat.h>

#include "core/atomic_file.hpp"
#include "core/errors.hpp"
#include "core/input_file.hpp"
#include "core/output_target.hpp"

namespace {

namespace fs = std::filesystem;

fs::path freshFolder(const std::string& name) {
    const fs::path d = fs::path(::testing::TempDir()) / ("outputs_" + name);
    fs::remove_all(d);
    fs::create_directories(d);
    return d;
}

std::string contentsOf(const fs::path& p) {
    std::ifstream in(p, std::ios::binary);
    return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

std::size_t entriesIn(const fs::path& d) {
    return std::size_t(std::distance(fs::directory_iterator(d), fs::directory_iterator()));
}

// The InputError's message, or "" when none was thrown.
template <typename F>
std::string inputErrorOf(F f) {
    try {
        f();
    } catch (const dacrt::InputError& e) {
        return e.what();
    }
    return {};
}

}  // namespace

TEST(OutputBatch, CommitPutsEveryFileInPlaceAndNoTemporary) {
    const fs::path d = freshFolder("commit");
    {
        dacrt::OutputBatch batch;
        batch.add((d / "a.txt").string(), "alpha");
        batch.add((d / "b.txt").string(), "beta");
        EXPECT_FALSE(fs::exists(d / "a.txt")) << "a file must not have its name before the batch commits";
        batch.commit();
    }
    EXPECT_EQ(contentsOf(d / "a.txt"), "alpha");
    EXPECT_EQ(contentsOf(d / "b.txt"), "beta");
    EXPECT_EQ(entriesIn(d), 2u);
}

TEST(OutputBatch, AFailedFileLeavesNoneOfTheBatch) {
    const fs::path d = freshFolder("none");
    {
        std::ofstream(d / "a.txt") << "the old file";
        dacrt::OutputBatch batch;
        batch.add((d / "a.txt").string(), "new");
        EXPECT_NE(inputErrorOf([&] { batch.add((d / "missing" / "b.txt").string(), "beta"); }), "");
    }
    EXPECT_EQ(contentsOf(d / "a.txt"), "the old file");
    EXPECT_EQ(entriesIn(d), 1u) << "a temporary was left behind";
}

TEST(OutputBatch, AFullDeviceIsAnErrorNamingTheFile) {
    const std::string message = inputErrorOf([] { dacrt::writeFileAtomically("/dev/full", "bytes"); });
    EXPECT_NE(message.find("/dev/full"), std::string::npos) << message;
    EXPECT_NE(message.find("No space left"), std::string::npos) << message;
}

TEST(OutputBatch, TheFileSizeLimitIsAnErrorAndLeavesNoFile) {
    const fs::path d = freshFolder("fsize");
    rlimit old{};
    ASSERT_EQ(getrlimit(RLIMIT_FSIZE, &old), 0);
    const auto oldHandler = std::signal(SIGXFSZ, SIG_IGN);  // as the commands set it (app/interrupt_cleanup)
    rlimit small = old;
    small.rlim_cur = 4096;
    ASSERT_EQ(setrlimit(RLIMIT_FSIZE, &small), 0);
    const std::string message =
        inputErrorOf([&] { dacrt::writeFileAtomically((d / "big.bin").string(), std::string(100000, 'x')); });
    setrlimit(RLIMIT_FSIZE, &old);
    std::signal(SIGXFSZ, oldHandler);
    EXPECT_NE(message.find("File too large"), std::string::npos) << message;
    EXPECT_EQ(entriesIn(d), 0u);
}

TEST(OutputBatch, DevicesAreWrittenThroughNotReplaced) {
    dacrt::writeFileAtomically("/dev/null", "discarded");
    struct stat st{};
    ASSERT_EQ(stat("/dev/null", &st), 0);
    EXPECT_TRUE(S_ISCHR(st.st_mode));
}

TEST(OutputBatch, AFifoIsWrittenThrough) {
    const fs::path d = freshFolder("fifo");
    const fs::path fifo = d / "pipe";
    ASSERT_EQ(mkfifo(fifo.c_str(), 0600), 0);
    std::string received;
    std::thread reader([&] { received = contentsOf(fifo); });
    dacrt::writeFileAtomically(fifo.string(), "through the pipe");
    reader.join();
    EXPECT_EQ(received, "through the pipe");
    EXPECT_TRUE(fs::is_fifo(fifo));
}

TEST(OutputBatch, ALinkIsFollowedAndKept) {
    const fs::path d = freshFolder("link");
    std::ofstream(d / "target.txt") << "old";
    fs::create_symlink(d / "target.txt", d / "link.txt");
    dacrt::writeFileAtomically((d / "link.txt").string(), "new");
    EXPECT_TRUE(fs::is_symlink(d / "link.txt"));
    EXPECT_EQ(contentsOf(d / "target.txt"), "new");
}

TEST(OutputTarget, RefusesFoldersAndDanglingLinks) {
    const fs::path d = freshFolder("refused");
    EXPECT_NE(inputErrorOf([&] { dacrt::resolveOutputTarget(d.string()); }).find("is a folder"), std::string::npos);
    fs::create_symlink(d / "nowhere" / "x.png", d / "dangling.png");
    const std::string dangling = inputErrorOf([&] { dacrt::resolveOutputTarget((d / "dangling.png").string()); });
    EXPECT_NE(dangling.find("does not exist"), std::string::npos) << dangling;
    EXPECT_TRUE(dacrt::resolveOutputTarget("/dev/null").writeThrough);
    EXPECT_FALSE(dacrt::resolveOutputTarget((d / "new.png").string()).exists);
}

TEST(InputFile, ReadsRegularFilesOnlyAndWithinTheLimit) {
    const fs::path d = freshFolder("inputs");
    std::ofstream(d / "small.bin") << "0123456789";
    EXPECT_EQ(dacrt::readRegularInput((d / "small.bin").string(), 0).size(), 10u);
    const std::string tooBig = inputErrorOf([&] { dacrt::readRegularInput((d / "small.bin").string(), 4); });
    EXPECT_NE(tooBig.find("more than the 4 bytes"), std::string::npos) << tooBig;
    ASSERT_EQ(mkfifo((d / "pipe").c_str(), 0600), 0);
    // No writer: a read that opened the FIFO would wait forever.
    EXPECT_NE(inputErrorOf([&] { dacrt::readRegularInput((d / "pipe").string(), 0); }).find("is a FIFO"), std::string::npos);
    EXPECT_NE(inputErrorOf([] { dacrt::readRegularInput("/dev/zero", 0); }).find("is a character device"),
              std::string::npos);
    EXPECT_NE(inputErrorOf([&] { dacrt::readRegularInput(d.string(), 0); }).find("is a folder"), std::string::npos);
    EXPECT_NE(inputErrorOf([&] { dacrt::readRegularInput((d / "absent").string(), 0); }).find("no such file"),
              std::string::npos);
}
