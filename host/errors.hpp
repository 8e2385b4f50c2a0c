#pragma once
#include <stdexcept>
#include <string>

namespace dacrt {

// Bad user input (files, options, scenes): the CLI prints the message and exits with 2.
class InputError : public std::runtime_error {
public:
    using std::runtime_error::runtime_error;
};

}  // namespace dacrt
