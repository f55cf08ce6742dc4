#pragma once
// Lists of option names for help and error messages.
#include <span>
#include <string>

namespace raypack {

/// The names joined by '|', e.g. "bvh2|bvh4|grid".
inline std::string names_joined(std::span<const char* const> names) {
    std::string list;
    for (const char* name : names) {
        if (!list.empty()) list += '|';
        list += name;
    }
    return list;
}

}  // namespace raypack
