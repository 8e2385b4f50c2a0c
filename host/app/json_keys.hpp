#pragma once
// JSON keys for scripts: snake_case, no spaces or punctuation ("device: ray ids and scratch"
// becomes "device_ray_ids_and_scratch").
#include <cctype>
#include <string>
#include <string_view>

namespace dacrt {

inline std::string jsonKey(std::string_view name) {
    std::string key;
    for (char c : name) {
        const unsigned char u = static_cast<unsigned char>(c);
        if (std::isalnum(u)) key += char(std::tolower(u));
        else if (!key.empty() && key.back() != '_') key += '_';
    }
    while (!key.empty() && key.back() == '_') key.pop_back();
    return key;
}

}  // namespace dacrt
