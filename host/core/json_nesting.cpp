#include "core/json_nesting.hpp"

namespace dacrt {

JsonNesting jsonNesting(std::string_view text, std::size_t limit) {
    JsonNesting deepest;
    std::size_t depth = 0;
    bool inString = false, escaped = false;
    for (std::size_t i = 0; i < text.size(); ++i) {
        const char c = text[i];
        if (inString) {
            if (escaped) escaped = false;
            else if (c == '\\') escaped = true;
            else if (c == '"') inString = false;
            continue;
        }
        if (c == '"') {
            inString = true;
        } else if (c == '{' || c == '[') {
            if (++depth > deepest.depth) {
                deepest = {depth, i};
                if (depth > limit) break;
            }
        } else if ((c == '}' || c == ']') && depth > 0) {
            --depth;
        }
    }
    return deepest;
}

}  // namespace dacrt
