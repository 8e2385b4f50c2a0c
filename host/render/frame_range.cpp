#include "render/frame_range.hpp"

#include <cmath>
#include <sstream>

#include "core/errors.hpp"

namespace dacrt {
namespace {

const char* kRangeShape =
    "a range is FIRST:LAST or FIRST:LAST:STEP, inclusive, frame numbers integers >= 0 (like 1:250 or 0:100:5)";

// Digits only: no sign, no spaces, no exponent, so that "1e3" or "-0" never pass as frame numbers.
std::int64_t frameNumber(const std::string& range, const std::string& part, const char* what) {
    if (part.empty() || part.size() > 9 || part.find_first_not_of("0123456789") != std::string::npos)
        throw InputError("--frames " + range + ": '" + part + "' is not a " + what + " (an integer from 0 to " +
                         std::to_string(kMaxFrameNumber) + "); " + kRangeShape);
    return std::stoll(part);
}

// The whole text as one number (std::stod alone accepts "2s" as 2).
std::optional<double> wholeNumber(const std::string& text) {
    try {
        std::size_t used = 0;
        const double v = std::stod(text, &used);
        if (used == text.size()) return v;
    } catch (const std::exception&) {
    }
    return std::nullopt;
}

}  // namespace

std::string FrameRange::text() const {
    std::string s = std::to_string(first);  // appended piece by piece: GCC 12 warns falsely on a chain of operator+
    s += ':';
    s += std::to_string(last);
    if (step != 1) {
        s += ':';
        s += std::to_string(step);
    }
    return s;
}

FrameRange parseFrameRange(const std::string& text) {
    std::vector<std::string> parts;
    std::stringstream s(text);
    for (std::string part; std::getline(s, part, ':');) parts.push_back(part);
    if (!text.empty() && text.back() == ':') parts.push_back("");
    if (parts.size() < 2 || parts.size() > 3) throw InputError("--frames " + text + ": " + kRangeShape);
    FrameRange r;
    r.first = frameNumber(text, parts[0], "frame number");
    r.last = frameNumber(text, parts[1], "frame number");
    if (parts.size() == 3) {
        r.step = frameNumber(text, parts[2], "step");
        if (r.step < 1) throw InputError("--frames " + text + ": the step must be at least 1");
    }
    if (r.first > r.last)
        throw InputError("--frames " + text + ": the first frame " + std::to_string(r.first) +
                         " comes after the last " + std::to_string(r.last) + " (the range is inclusive and counts up)");
    if (r.count() > kMaxFramesInRange)
        throw InputError("--frames " + text + ": " + std::to_string(r.count()) + " frames; a range holds at most " +
                         std::to_string(kMaxFramesInRange) + " (split it over several runs)");
    return r;
}

double parseFps(const std::string& text) {
    const std::optional<double> fps = wholeNumber(text);
    if (!fps || !std::isfinite(*fps) || *fps <= 0.0)
        throw InputError("--fps " + text +
                         ": frames per second must be a finite number above 0 (frame n is at n / fps seconds)");
    return *fps;
}

double parseTime(const std::string& text) {
    const std::optional<double> t = wholeNumber(text);
    if (!t || !std::isfinite(*t) || *t < 0.0)
        throw InputError("--time " + text + ": the instant must be a finite number of seconds, 0 or more");
    return *t;
}

double timeOfFrame(std::int64_t frame, double fps) { return double(frame) / fps; }

}  // namespace dacrt
