#pragma once

namespace dacrt {

// Parses the command line and runs the chosen subcommand; returns its exit code
// (cmd/exit_codes.hpp). Errors are one line on stderr.
int runCli(int argc, char** argv);

}  // namespace dacrt
