#pragma once
// The instants a render covers: one (--time T, default 0 s), or a range of frame numbers
// (--frames A:B[:S], inclusive, every S-th) at --fps F, frame n at n / F seconds.
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

namespace dacrt {

// Frame numbers are integers from 0; a range holds at most this many frames, so that the list
// of a shard's frames is never a memory problem.
constexpr std::int64_t kMaxFrameNumber = 999'999'999;
constexpr std::int64_t kMaxFramesInRange = 1'000'000;
constexpr double kDefaultFps = 24.0;

struct FrameRange {
    std::int64_t first = 0;
    std::int64_t last = 0;
    std::int64_t step = 1;

    std::int64_t count() const { return (last - first) / step + 1; }
    std::int64_t frameAt(std::int64_t index) const { return first + index * step; }  // index 0..count()-1
    std::string text() const;  // "A:B" or "A:B:S", as --frames takes it
};

// Throws InputError naming --frames and saying what a range looks like.
FrameRange parseFrameRange(const std::string& text);

// --fps: a finite number above 0; throws InputError quoting the text otherwise.
double parseFps(const std::string& text);

// --time: a finite number of seconds, 0 or more; throws InputError quoting the text otherwise.
double parseTime(const std::string& text);

double timeOfFrame(std::int64_t frame, double fps);

// One instant to render: a frame number of a range (none for --time or a single render) and
// its time in seconds.
struct FrameInstant {
    std::optional<std::int64_t> frame;
    double time = 0.0;
};

}  // namespace dacrt
