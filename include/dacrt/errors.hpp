#pragma once
// The two kinds of failure dacrt reports; the command line maps each to its own exit code
// (host/app/exit_codes.hpp).
#include <stdexcept>
#include <string>

namespace dacrt {

// Bad input (a file, an option, a scene, a size the machine or device cannot hold): the
// message names the problem, and the run stops before any long work where it can.
class InputError : public std::runtime_error {
public:
    using std::runtime_error::runtime_error;
};

// A broken promise inside dacrt (an estimate the kernel relies on did not hold, work that
// stopped making progress): not the user's fault, and worth a bug report.
class InternalError : public std::logic_error {
public:
    using std::logic_error::logic_error;
};

}  // namespace dacrt
