#pragma once
// Runs the dacrt binary as a user would, collecting its exit code and output.
#include <array>
#include <cstdio>
#include <string>

#include <sys/wait.h>

namespace dacrt::test {

struct CommandResult {
    int code = -1;
    std::string output;  // stdout and stderr together
};

// environment: assignments put before the command, e.g. "DACRT_SIMD_TARGET=SCALAR".
inline CommandResult runDacrt(const std::string& args, const std::string& environment = "") {
    const std::string command = (environment.empty() ? "" : "env " + environment + " ") + std::string(DACRT_BINARY) +
                                " " + args + " 2>&1";
    CommandResult r;
    FILE* pipe = popen(command.c_str(), "r");
    if (!pipe) return r;
    std::array<char, 4096> buffer{};
    std::size_t n;
    while ((n = fread(buffer.data(), 1, buffer.size(), pipe)) > 0) r.output.append(buffer.data(), n);
    const int status = pclose(pipe);
    r.code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
    return r;
}

}  // namespace dacrt::test
