#pragma once
// A scan of JSON text for its nesting depth, before any recursive parser sees it: a file
// nested 100,000 levels deep must be an input error, not a stack overflow.
#include <cstddef>
#include <string_view>

namespace dacrt {

struct JsonNesting {
    std::size_t depth = 0;   // the deepest nesting of objects and arrays
    std::size_t offset = 0;  // where it was first reached (byte offset into the text)
};

// Brackets inside strings (with their escapes) do not count. Stops once `limit` is exceeded.
JsonNesting jsonNesting(std::string_view text, std::size_t limit);

}  // namespace dacrt
