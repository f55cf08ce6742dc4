#include "scene/atomic_file.h"

#include <filesystem>
#include <random>
#include <stdexcept>
#include <system_error>

namespace raypack {

void write_atomically(const std::string& path, const std::function<void(const std::string&)>& write) {
    namespace fs = std::filesystem;
    const fs::path target(path);
    std::random_device rd;
    // Keep the extension last: image writers pick the format from it.
    const fs::path tmp = target.parent_path() /
                         (target.stem().string() + ".tmp" + std::to_string(rd()) + target.extension().string());
    try {
        write(tmp.string());
    } catch (...) {
        std::error_code ec;
        fs::remove(tmp, ec);
        throw;
    }
    std::error_code ec;
    fs::rename(tmp, target, ec);
    if (ec) {
        fs::remove(tmp, ec);
        throw std::runtime_error(path + ": cannot replace the file: " + ec.message());
    }
}

}  // namespace raypack
