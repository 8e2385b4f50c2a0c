#pragma once
// Progress on stderr: a bar with the count and an estimate of the time left when stderr is a
// terminal; otherwise one line per stage (a log stays readable, a terminal stays quiet).
#include <cstddef>
#include <mutex>
#include <string>

#include "core/timing.hpp"

namespace dacrt {

class Progress {
public:
    // `label` starts every line ("dacrt bench"); `total` steps make the whole.
    Progress(std::string label, std::size_t total);
    ~Progress();  // clears the bar

    // A new stage: a line of its own when stderr is not a terminal.
    void stage(const std::string& what);
    // A finished stage's result: a line of its own on a terminal too (above the bar).
    void note(const std::string& what);
    // One step done (`what` shown beside the bar on a terminal). Safe from several threads.
    void step(const std::string& what = {});
    // Fraction done, for work counted in other units (rays, blocks). Safe from several threads.
    void fraction(double done, const std::string& what = {});

private:
    void draw(double done, const std::string& what);

    std::string label_;
    std::size_t total_;
    std::size_t done_ = 0;
    bool terminal_;
    Clock::time_point start_;
    Clock::time_point lastDraw_{};
    std::mutex mutex_;
};

}  // namespace dacrt
