#pragma once
// The two kinds of failure the library reports, defined once in the public header (the
// command line maps each to its own exit code: host/app/exit_codes.hpp).
#include <dacrt/errors.hpp>
