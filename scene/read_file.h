#pragma once
// Private to the loaders: a whole scene file as text, or a SceneError naming it.
#include <cerrno>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <system_error>

#include "scene/load.h"

namespace raypack {

inline std::string read_scene_file(const std::string& path) {
    std::error_code ec;
    if (std::filesystem::is_directory(path, ec)) throw SceneError(path, 0, "is a directory, not a scene file");
    errno = 0;
    std::ifstream in(path, std::ios::binary);
    if (!in)
        throw SceneError(path, 0, std::string("cannot open file: ") + (errno ? std::strerror(errno) : "unknown error"));
    std::string text{std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
    if (in.bad()) throw SceneError(path, 0, "read error");
    return text;
}

}  // namespace raypack
