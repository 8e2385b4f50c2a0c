// The frame time against error plot, read back as an image.
#include <array>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <set>
#include <string>
#include <vector>

#include <OpenImageIO/imageio.h>
#include <gtest/gtest.h>

#include "errors.hpp"
#include "plot.hpp"

namespace {

using dacrt::PlotPoint;
using Rgb = std::array<std::uint8_t, 3>;

// The palette's first two entries (plot.hpp): series are coloured in order of first appearance.
constexpr Rgb kFirstSeriesColour{31, 119, 180};
constexpr Rgb kSecondSeriesColour{255, 127, 14};

std::string temp(const std::string& name) { return ::testing::TempDir() + "/plot_" + name; }

struct Image {
    int width = 0, height = 0, channels = 0;
    std::vector<Rgb> pixels;
};

Image readBack(const std::string& path) {
    auto in = OIIO::ImageInput::open(path);
    if (!in) throw std::runtime_error(path + ": " + OIIO::geterror());
    Image image;
    image.width = in->spec().width;
    image.height = in->spec().height;
    image.channels = in->spec().nchannels;
    image.pixels.resize(std::size_t(image.width) * std::size_t(image.height));
    if (image.channels != 3 || !in->read_image(0, 0, 0, 3, OIIO::TypeDesc::UINT8, image.pixels.data()))
        throw std::runtime_error(path + ": not an RGB8 image: " + in->geterror());
    return image;
}

std::size_t count(const Image& image, const Rgb& colour) {
    std::size_t n = 0;
    for (const Rgb& p : image.pixels) n += p == colour;
    return n;
}

std::string bytesOf(const std::string& path) {
    std::ifstream f(path, std::ios::binary);
    return {std::istreambuf_iterator<char>(f), std::istreambuf_iterator<char>()};
}

// Two series, each with a Pareto front, zero errors and a default configuration.
std::vector<PlotPoint> benchmarkPoints() {
    return {
        {.series = "cpu", .label = "r1", .timeMs = 180.0, .error = 0.0, .pareto = true, .highlighted = true, .labelled = true},
        {.series = "cpu", .label = "r8", .timeMs = 45.0, .error = 2e-4, .pareto = true, .labelled = true},
        {.series = "cpu", .label = "r64", .timeMs = 70.0, .error = 5e-3},
        {.series = "gpu", .label = "wg64", .timeMs = 2.2, .error = 3e-5, .pareto = true, .labelled = true},
        {.series = "gpu", .label = "wg256", .timeMs = 3.9, .error = 0.0, .pareto = true, .highlighted = true, .labelled = true},
        {.series = "gpu", .label = "wg32", .timeMs = 6.0, .error = 0.02, .labelled = true},
    };
}

void plot(const std::string& path, const std::vector<PlotPoint>& points) {
    dacrt::writeTimeErrorPlot(path, "Frame time against error", "frame time (ms)", "error", points);
}

}  // namespace

TEST(Plot, WritesAnRgbImageWithEachSeriesInItsColour) {
    const std::string path = temp("two_series.png");
    plot(path, benchmarkPoints());
    const Image image = readBack(path);
    EXPECT_EQ(image.width, 1000);
    EXPECT_EQ(image.height, 700);
    EXPECT_EQ(image.channels, 3);
    const std::set<Rgb> colours(image.pixels.begin(), image.pixels.end());
    EXPECT_GT(colours.size(), 3u) << "the plot is (nearly) a single colour";
    EXPECT_GT(count(image, kFirstSeriesColour), 0u);
    EXPECT_GT(count(image, kSecondSeriesColour), 0u);
}

TEST(Plot, PointsAreDrawnInTheirSeriesColour) {
    // The legend shows each colour too, so only a difference proves that points are drawn.
    std::vector<PlotPoint> points = benchmarkPoints();
    const std::string before = temp("before.png"), after = temp("after.png");
    plot(before, points);
    points.push_back({.series = "gpu", .label = "extra", .timeMs = 12.0, .error = 0.3});
    plot(after, points);
    const Image a = readBack(before), b = readBack(after);
    EXPECT_GT(count(b, kSecondSeriesColour), count(a, kSecondSeriesColour));
    EXPECT_EQ(count(b, kFirstSeriesColour), count(a, kFirstSeriesColour));
}

TEST(Plot, ZeroErrorsAndHugeRangesStayInsideTheImage) {
    const std::string path = temp("extremes.png");
    plot(path, {{.series = "only", .label = "fast", .timeMs = 1e-3, .error = 0.0, .pareto = true},
                {.series = "only", .label = "slow", .timeMs = 1e5, .error = 1e-15, .pareto = true},
                {.series = "only", .label = "worst", .timeMs = 1e5, .error = 1.0}});
    EXPECT_GT(count(readBack(path), kFirstSeriesColour), 0u);
}

TEST(Plot, SameInputGivesTheSameBytes) {
    const std::string a = temp("same_a.png"), b = temp("same_b.png");
    plot(a, benchmarkPoints());
    plot(b, benchmarkPoints());
    const std::string bytes = bytesOf(a);
    EXPECT_FALSE(bytes.empty());
    EXPECT_EQ(bytes, bytesOf(b));
}

TEST(Plot, NoPointsThrows) {
    const std::string path = temp("empty.png");
    std::filesystem::remove(path);
    EXPECT_THROW(plot(path, {}), dacrt::InputError);
    EXPECT_FALSE(std::filesystem::exists(path));
}

TEST(Plot, PointsOutsideTheAxesThrow) {
    for (const PlotPoint& bad : {PlotPoint{.series = "s", .label = "bad", .timeMs = 0.0, .error = 0.1},
                                 PlotPoint{.series = "s", .label = "bad", .timeMs = -1.0, .error = 0.1},
                                 PlotPoint{.series = "s", .label = "bad", .timeMs = 1.0, .error = -0.1},
                                 PlotPoint{.series = "s", .label = "bad", .timeMs = 1.0, .error = 1.5},
                                 PlotPoint{.series = "s", .label = "bad", .timeMs = 1.0, .error = std::nan("")}})
        EXPECT_THROW(plot(temp("bad.png"), {bad}), dacrt::InputError) << bad.timeMs << " ms, error " << bad.error;
}

TEST(Plot, UnwritablePathThrows) {
    EXPECT_THROW(plot("/nonexistent-dacrt-dir/plot.png", benchmarkPoints()), dacrt::InputError);
    EXPECT_THROW(plot(temp("plot.not-an-image-format"), benchmarkPoints()), dacrt::InputError);
}
