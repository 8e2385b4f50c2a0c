// What render does with the outputs it is given: every name of a range checked before any
// work, devices and FIFOs written through, failed writes reported with no partial output.
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <set>
#include <string>
#include <thread>

#include <gtest/gtest.h>
#include <sys/stat.h>

#include "support/cli_support.hpp"
#include "support/fixtures.hpp"

namespace {

namespace fs = std::filesystem;
using dacrt::test::CommandResult;

CommandResult run(const std::string& args) { return dacrt::test::runDacrt(args); }

// A command line through the shell, for a limit set before dacrt starts.
CommandResult runInShell(const std::string& shellPrefix, const std::string& args) {
    return dacrt::test::runDacrt(args, "sh -c '" + shellPrefix + "; exec \"$0\" \"$@\"'");
}

fs::path freshFolder(const std::string& name) {
    const fs::path d = fs::path(::testing::TempDir()) / ("cli_outputs_" + name);
    fs::remove_all(d);
    fs::create_directories(d);
    return d;
}

std::set<std::string> namesIn(const fs::path& d) {
    std::set<std::string> names;
    for (const auto& e : fs::directory_iterator(d)) names.insert(e.path().filename().string());
    return names;
}

const std::string kScene = dacrt::test::fixture("quad_u8_camera.gltf");

}  // namespace

TEST(CliOutputs, TwoNamesThatMeetAtALaterFrameAreRefusedBeforeAnyFrame) {
    const fs::path d = freshFolder("meet");
    const CommandResult r = run("render " + kScene + " --size 8x6 --frames 0:20 -o " + (d / "a_%d.png").string() +
                                " --depth-png " + (d / "a_1%d.png").string());
    EXPECT_EQ(r.code, 2) << r.output;
    EXPECT_NE(r.output.find("a_10.png (frame 10): the same file as --depth-png"), std::string::npos) << r.output;
    EXPECT_NE(r.output.find("a_10.png (frame 0)"), std::string::npos) << r.output;
    EXPECT_TRUE(namesIn(d).empty()) << "a frame was written before the clash was found";
}

TEST(CliOutputs, AnOutputThatIsTheInputAtSomeFrameIsRefused) {
    const fs::path d = freshFolder("input");
    fs::copy_file(kScene, d / "scene_3.gltf");
    const CommandResult r = run("render " + (d / "scene_3.gltf").string() + " --size 8x6 --frames 0:5 --stats " +
                                (d / "scene_%d.gltf").string());
    EXPECT_EQ(r.code, 2) << r.output;
    EXPECT_NE(r.output.find("(frame 3): the same file as the input"), std::string::npos) << r.output;
    EXPECT_EQ(namesIn(d), std::set<std::string>{"scene_3.gltf"});
}

TEST(CliOutputs, AFolderAtALaterFrameIsRefusedBeforeAnyFrame) {
    const fs::path d = freshFolder("folder");
    fs::create_directory(d / "f_4.png");
    const CommandResult r = run("render " + kScene + " --size 8x6 --frames 0:6 -o " + (d / "f_%d.png").string());
    EXPECT_EQ(r.code, 2) << r.output;
    EXPECT_NE(r.output.find("f_4.png: is a folder"), std::string::npos) << r.output;
    EXPECT_EQ(namesIn(d), std::set<std::string>{"f_4.png"});
}

TEST(CliOutputs, SkipExistingDoesNotTakeADeviceForAFinishedFrame) {
    const CommandResult r = run("render " + kScene + " --size 8x6 --skip-existing -o /dev/null");
    EXPECT_EQ(r.code, 0) << r.output;
    EXPECT_NE(r.output.find("wrote /dev/null"), std::string::npos) << r.output;
}

TEST(CliOutputs, DevicesAreWrittenThroughNeverReplaced) {
    const CommandResult r = run("render " + kScene + " --size 8x6 -o /dev/null --aov /dev/null --stats /dev/null");
    EXPECT_EQ(r.code, 0) << r.output;
    struct stat st{};
    ASSERT_EQ(stat("/dev/null", &st), 0);
    EXPECT_TRUE(S_ISCHR(st.st_mode)) << "/dev/null was replaced";
}

TEST(CliOutputs, AFifoGetsTheImageInTheFormatOfItsUse) {
    const fs::path d = freshFolder("fifo");
    const fs::path fifo = d / "image_pipe";
    ASSERT_EQ(mkfifo(fifo.c_str(), 0600), 0);
    std::string received;
    std::thread reader([&] {
        std::ifstream in(fifo, std::ios::binary);
        received.assign(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
    });
    const CommandResult r = run("render " + kScene + " --size 8x6 -o " + fifo.string());
    reader.join();
    EXPECT_EQ(r.code, 0) << r.output;
    EXPECT_EQ(received.substr(0, 8), std::string("\x89PNG\r\n\x1a\n", 8)) << "a PNG through a pipe named without extension";
    EXPECT_TRUE(fs::is_fifo(fifo));
}

TEST(CliOutputs, AFullDeviceFailsTheRunAndLeavesNoOtherOutputOfTheFrame) {
    const fs::path d = freshFolder("full");
    const CommandResult r =
        run("render " + kScene + " --size 8x6 -o " + (d / "shaded.png").string() + " --aov /dev/full --stats " +
            (d / "stats.json").string());
    EXPECT_EQ(r.code, 2) << r.output;
    EXPECT_NE(r.output.find("/dev/full: cannot write the file"), std::string::npos) << r.output;
    EXPECT_TRUE(namesIn(d).empty()) << "the frame's other outputs must go with the failed one";
}

TEST(CliOutputs, TheFileSizeLimitFailsTheRunWithAMessageAndNoPartialFile) {
    const fs::path d = freshFolder("fsize");
    const CommandResult r = runInShell("ulimit -f 4", "render " + kScene + " --size 256x192 -o " + (d / "a.png").string() +
                                                          " --aov " + (d / "a.exr").string());
    EXPECT_EQ(r.code, 2) << r.output;
    EXPECT_NE(r.output.find("File too large"), std::string::npos) << r.output;
    EXPECT_TRUE(namesIn(d).empty());
}

TEST(CliOutputs, InputsThatAreNotRegularFilesAreRefusedWithoutWaiting) {
    const fs::path d = freshFolder("inputs");
    ASSERT_EQ(mkfifo((d / "scene.gltf").c_str(), 0600), 0);
    const CommandResult fifo = run("render " + (d / "scene.gltf").string() + " --size 8x6");
    EXPECT_EQ(fifo.code, 2) << fifo.output;
    EXPECT_NE(fifo.output.find("is a FIFO"), std::string::npos) << fifo.output;
    const CommandResult device = run("compare /dev/zero /dev/zero");
    EXPECT_EQ(device.code, 2) << device.output;
    EXPECT_NE(device.output.find("is a character device"), std::string::npos) << device.output;
}

// OpenImageIO lives in a module loaded on the first image (core/image_codecs.hpp): a run that
// writes no image never needs it, and one that does, without it, fails before tracing, naming
// where it looked and leaving nothing behind.
TEST(CliOutputs, TheImageCodecsModuleIsLoadedOnlyForImagesAndItsAbsenceIsNamed) {
    const fs::path d = freshFolder("codecs");
    const std::string missing = "DACRT_CODECS_MODULE=" + (d / "no_such_module.so").string();
    const CommandResult statsOnly =
        dacrt::test::runDacrt("render " + kScene + " --size 8x6 --stats " + (d / "s.json").string(), missing);
    EXPECT_EQ(statsOnly.code, 0) << statsOnly.output;
    EXPECT_TRUE(fs::exists(d / "s.json"));
    const CommandResult image =
        dacrt::test::runDacrt("render " + kScene + " --size 8x6 -o " + (d / "a.png").string() + " --stats " +
                                  (d / "t.json").string(), missing);
    EXPECT_NE(image.code, 0) << image.output;
    EXPECT_NE(image.output.find((d / "no_such_module.so").string() + ": "), std::string::npos) << image.output;
    EXPECT_NE(image.output.find("DACRT_CODECS_MODULE"), std::string::npos) << image.output;
    EXPECT_EQ(image.output.find(" rays"), std::string::npos) << "traced before finding it cannot write: " << image.output;
    EXPECT_EQ(namesIn(d), (std::set<std::string>{"s.json"}));
}
