#include "scene/atomic_file.h"

#include <csignal>
#include <cstring>
#include <filesystem>
#include <random>
#include <stdexcept>
#include <system_error>

#include <unistd.h>

namespace raypack {
namespace {

// The temporary being written, for the signal handler: Ctrl-C or a TERM
// during a write removes it, so an interrupted command leaves the old file
// and nothing else. (SIGKILL cannot be caught: the old file is still intact,
// the temporary stays.) raypack writes one output at a time.
char g_temporary[4096];
volatile std::sig_atomic_t g_writing = 0;

extern "C" void remove_temporary_and_exit(int sig) {
    if (g_writing) ::unlink(g_temporary);  // async-signal-safe
    std::signal(sig, SIG_DFL);
    std::raise(sig);
}

void watch_interrupts() {
    static const bool installed = [] {
        for (int sig : {SIGINT, SIGTERM, SIGHUP}) std::signal(sig, remove_temporary_and_exit);
        return true;
    }();
    (void)installed;
}

}  // namespace

void write_atomically(const std::string& path, const std::function<void(const std::string&)>& write) {
    namespace fs = std::filesystem;
    const fs::path target(path);
    std::random_device rd;
    // Keep the extension last: image writers pick the format from it.
    const fs::path tmp = target.parent_path() /
                         (target.stem().string() + ".tmp" + std::to_string(rd()) + target.extension().string());
    const std::string tmp_name = tmp.string();
    const bool watched = tmp_name.size() < sizeof g_temporary;
    if (watched) {
        watch_interrupts();
        std::memcpy(g_temporary, tmp_name.c_str(), tmp_name.size() + 1);
        g_writing = 1;
    }
    struct StopWatching {
        ~StopWatching() { g_writing = 0; }
    } stop;
    try {
        write(tmp_name);
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
