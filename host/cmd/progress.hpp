#pragma once
// A progress bar on stderr when it is a terminal; silent otherwise.
#include <algorithm>
#include <cstddef>
#include <iostream>
#include <string>

#include <unistd.h>

namespace dacrt {

class Progress {
public:
    Progress(std::size_t total) : total_(total), enabled_(isatty(STDERR_FILENO) != 0) {}
    void step(const std::string& what) {
        ++done_;
        if (!enabled_) return;
        const int width = 30, filled = int(double(width) * double(done_) / double(std::max<std::size_t>(total_, 1)));
        std::cerr << "\r[" << std::string(std::size_t(filled), '=') << std::string(std::size_t(width - filled), ' ')
                  << "] " << done_ << "/" << total_ << " " << what.substr(0, 60) << "\033[K" << std::flush;
    }
    void finish() {
        if (enabled_) std::cerr << "\r\033[K" << std::flush;
    }

private:
    std::size_t total_, done_ = 0;
    bool enabled_;
};

}  // namespace dacrt
