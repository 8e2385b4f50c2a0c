#include "app/progress.hpp"

#include <algorithm>
#include <cstdio>
#include <iostream>

#include <unistd.h>

namespace dacrt {

Progress::Progress(std::string label, std::size_t total)
    : label_(std::move(label)), total_(std::max<std::size_t>(total, 1)), terminal_(isatty(STDERR_FILENO) != 0),
      start_(Clock::now()) {}

Progress::~Progress() {
    if (terminal_) std::cerr << "\r\033[K" << std::flush;
}

void Progress::stage(const std::string& what) {
    std::lock_guard<std::mutex> lock(mutex_);
    if (!terminal_) std::cerr << label_ << ": " << what << "\n";
}

void Progress::note(const std::string& what) {
    std::lock_guard<std::mutex> lock(mutex_);
    if (terminal_) std::cerr << "\r\033[K";
    std::cerr << label_ << ": " << what << "\n";
    lastDraw_ = {};  // the bar comes back at the next step
}

void Progress::step(const std::string& what) {
    std::lock_guard<std::mutex> lock(mutex_);
    ++done_;
    draw(double(done_) / double(total_), what);
}

void Progress::fraction(double done, const std::string& what) {
    std::lock_guard<std::mutex> lock(mutex_);
    draw(done, what);
}

void Progress::draw(double done, const std::string& what) {
    if (!terminal_) return;
    const Clock::time_point now = Clock::now();
    if (done < 1.0 && now - lastDraw_ < std::chrono::milliseconds(100)) return;  // a terminal needs no more
    lastDraw_ = now;
    const double elapsed = msSince(start_) / 1000.0;
    char eta[32] = "";
    if (done > 0.01 && done < 1.0) std::snprintf(eta, sizeof eta, ", %.0f s left", elapsed * (1.0 - done) / done);
    const int width = 30, filled = int(double(width) * std::clamp(done, 0.0, 1.0));
    std::cerr << "\r" << label_ << " [" << std::string(std::size_t(filled), '=') << std::string(std::size_t(width - filled), ' ')
              << "] " << int(done * 100.0) << "%" << eta << " " << what.substr(0, 50) << "\033[K" << std::flush;
}

}  // namespace dacrt
