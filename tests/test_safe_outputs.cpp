// An output file is replaced whole or not at all: a writer killed (SIGKILL)
// or interrupted (SIGINT, as by Ctrl-C) at any moment leaves the old file or
// the complete new one, never a truncated one; an interrupted writer also
// leaves no temporary behind.
#include <gtest/gtest.h>

#include <csignal>
#include <filesystem>
#include <fstream>
#include <string>

#include <fcntl.h>
#include <sys/wait.h>
#include <unistd.h>

#include "scene/ray_file.h"
#include "tests/temp_dir_test.h"
#include "tests/test_paths.h"

namespace raypack {
namespace {

namespace fs = std::filesystem;

/// Runs `raypack rays` writing 4M camera rays (128 MiB) over `out`, sends
/// `sig` after `delay_us`, and returns the wait status.
int write_and_signal(const fs::path& out, int sig, useconds_t delay_us) {
    const pid_t pid = fork();
    if (pid == 0) {
        const std::string cli = RAYPACK_CLI, path = out.string();
        const int null = ::open("/dev/null", O_WRONLY);
        ::dup2(null, 1);
        ::execl(cli.c_str(), cli.c_str(), "rays", "gen:balls:4", "--kind", "camera", "--res", "2048", "2048", "-o",
                path.c_str(), static_cast<char*>(nullptr));
        ::_exit(127);
    }
    ::usleep(delay_us);
    ::kill(pid, sig);
    int status = 0;
    ::waitpid(pid, &status, 0);
    return status;
}

void expect_old_or_complete(const fs::path& out, const std::string& old) {
    const std::string now = file_bytes(out);
    if (now == old) return;
    // Otherwise the writer finished: the whole new file, readable.
    const RayFile f = read_rays(out.string());
    EXPECT_EQ(f.rays.size(), 2048u * 2048u);
}

class SafeOutputs : public TempDirTest {};

TEST_F(SafeOutputs, KilledWriterLeavesTheOldFileOrTheWholeNewOne) {
    const fs::path out = dir_ / "out.rays";
    const std::string old = "the previous contents";
    for (useconds_t delay : {2000u, 20000u, 60000u, 120000u, 250000u, 2000000u}) {
        { std::ofstream(out, std::ios::binary) << old; }
        const int status = write_and_signal(out, SIGKILL, delay);
        SCOPED_TRACE("delay " + std::to_string(delay) + " us");
        EXPECT_TRUE((WIFSIGNALED(status) && WTERMSIG(status) == SIGKILL) || (WIFEXITED(status) && WEXITSTATUS(status) == 0));
        expect_old_or_complete(out, old);
    }
}

TEST_F(SafeOutputs, InterruptedWriterLeavesNoTemporary) {
    const fs::path out = dir_ / "out.rays";
    const std::string old = "the previous contents";
    int interrupted = 0;
    for (useconds_t delay : {2000u, 20000u, 60000u, 120000u, 250000u}) {
        { std::ofstream(out, std::ios::binary) << old; }
        const int status = write_and_signal(out, SIGINT, delay);
        SCOPED_TRACE("delay " + std::to_string(delay) + " us");
        if (WIFSIGNALED(status)) {
            EXPECT_EQ(WTERMSIG(status), SIGINT);  // ended by the signal, as a shell expects
            ++interrupted;
        } else {
            EXPECT_EQ(WEXITSTATUS(status), 0);
        }
        expect_old_or_complete(out, old);
        for (const auto& e : fs::directory_iterator(dir_))
            EXPECT_EQ(e.path().filename(), "out.rays") << "left behind: " << e.path();
    }
    EXPECT_GT(interrupted, 0) << "every writer finished before its signal: the test checked nothing";
}

}  // namespace
}  // namespace raypack
