#include "render/frame_pattern.hpp"

#include <cctype>
#include <filesystem>
#include <vector>

#include "core/errors.hpp"

namespace dacrt {
namespace {

constexpr std::size_t kMaxWidth = 18;  // digits of padding; wider than any frame number

// A piece of a name: literal text, or the frame number padded to `width` digits (0: none).
struct Piece {
    std::string text;
    bool frame = false;
    std::size_t width = 0;
};

// Splits a name into its pieces; `problem` is set (and the pieces are incomplete) when a '%'
// starts nothing this format knows.
std::vector<Piece> pieces(const std::string& name, std::string& problem) {
    std::vector<Piece> out(1);
    for (std::size_t i = 0; i < name.size(); ++i) {
        if (name[i] != '%') {
            out.back().text += name[i];
            continue;
        }
        if (i + 1 < name.size() && name[i + 1] == '%') {
            out.back().text += '%';
            ++i;
            continue;
        }
        std::size_t j = i + 1;
        std::size_t width = 0;
        if (j < name.size() && name[j] == '0') {
            ++j;
            const std::size_t digits = j;
            while (j < name.size() && std::isdigit(static_cast<unsigned char>(name[j]))) ++j;
            if (j == digits || j - digits > 2) {
                problem = "'%0' must be followed by a width from 1 to " + std::to_string(kMaxWidth) + " and 'd' (%04d)";
                return out;
            }
            width = std::stoul(name.substr(digits, j - digits));
            if (width < 1 || width > kMaxWidth) {
                problem = "the width of '%0Nd' must lie in 1.." + std::to_string(kMaxWidth);
                return out;
            }
        }
        if (j >= name.size() || name[j] != 'd') {
            problem.assign(1, '\'');  // piece by piece: GCC 12 warns falsely (-Wrestrict) on operator+ and on = "'"
            problem.append(name, i, j + 1 - i);  // append clips at the name's end
            problem +=
                "' is not a frame number: write %d or %04d (zero-padded to 4 digits) for the frame, %% for a "
                "literal percent sign";
            return out;
        }
        out.push_back(Piece{"", true, width});
        out.push_back(Piece{});
        i = j;
    }
    return out;
}

}  // namespace

bool checkFramePattern(const std::string& option, const std::string& name) {
    std::string problem;
    const std::vector<Piece> ps = pieces(name, problem);
    const std::string where = option + " " + name + ": ";
    if (!problem.empty()) throw InputError(where + problem);
    std::size_t frames = 0;
    for (const Piece& p : ps) frames += p.frame;
    if (frames > 1) throw InputError(where + "one frame number per name (%d or %0Nd), not " + std::to_string(frames));
    if (frames == 1 && std::filesystem::path(name).parent_path().string().find('%') != std::string::npos) {
        // The folder part of the escaped name: a '%' there is a frame number or an escape; only the former is refused.
        std::string folderProblem;
        for (const Piece& p : pieces(std::filesystem::path(name).parent_path().string(), folderProblem))
            if (p.frame)
                throw InputError(where +
                                 "the frame number goes in the file's name, not its folder (nothing creates a "
                                 "folder per frame)");
    }
    return frames == 1;
}

std::string expandFramePattern(const std::string& name, std::int64_t frame) {
    std::string problem;
    std::string out;
    for (const Piece& p : pieces(name, problem)) {
        if (!p.frame) {
            out += p.text;
            continue;
        }
        std::string digits = std::to_string(frame);
        if (digits.size() < p.width) digits.insert(0, p.width - digits.size(), '0');
        out += digits;
    }
    return out;
}

std::string suggestFramePattern(const std::string& name) {
    const std::filesystem::path p(name);
    return (p.parent_path() / (p.stem().string() + "_%04d" + p.extension().string())).string();
}

}  // namespace dacrt
