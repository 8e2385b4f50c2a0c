#pragma once

namespace dacrt {

// Parses the command line and runs the chosen subcommand. Exit codes: 0 success, 2 bad
// input or options (a one-line message on stderr), 1 an internal error.
int runCli(int argc, char** argv);

}  // namespace dacrt
