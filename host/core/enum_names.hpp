#pragma once
// One name table per enum, read by toString and by the command line's choices, so that a
// name is written once. An enum E opts in with a specialization of EnumNames<E>.
#include <array>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace dacrt {

template <typename E>
struct EnumNames;  // static constexpr std::array<std::pair<E, std::string_view>, N> table

template <typename E>
std::string toString(E value) {
    for (const auto& [v, name] : EnumNames<E>::table)
        if (v == value) return std::string(name);
    return "?";
}

template <typename E>
std::optional<E> parseEnum(std::string_view name) {
    for (const auto& [v, n] : EnumNames<E>::table)
        if (n == name) return v;
    return std::nullopt;
}

template <typename E>
std::vector<std::string> enumNameList() {
    std::vector<std::string> names;
    for (const auto& entry : EnumNames<E>::table) names.emplace_back(entry.second);
    return names;
}

}  // namespace dacrt
