// The image module (libraypack_image.so, render/image_module.h): commands
// that write no image never load OpenImageIO, and a missing or broken module
// is a clear error with a non-zero status, never a crash or an output file.
#include <gtest/gtest.h>
#include <sys/wait.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include "tests/test_paths.h"

namespace raypack {
namespace {

namespace fs = std::filesystem;

fs::path temp_dir() {
    const fs::path d = fs::temp_directory_path() / "raypack_test_image_module" /
                       ::testing::UnitTest::GetInstance()->current_test_info()->name();
    fs::create_directories(d);
    return d;
}

std::string read_file(const fs::path& p) {
    std::ifstream in(p, std::ios::binary);
    std::ostringstream text;
    text << in.rdbuf();
    return text.str();
}

struct Outcome {
    int status = -1;
    std::string log;  // stdout and stderr
};

/// Runs `env ENV raypack ARGS` with its output in a file of `dir`.
Outcome run_cli(const fs::path& dir, const std::string& env, const std::string& args) {
    const fs::path log = dir / "log.txt";
    const std::string cmd = "env " + env + " " + RAYPACK_CLI + " " + args + " >" + log.string() + " 2>&1";
    const int status = std::system(cmd.c_str());
    return {WIFEXITED(status) ? WEXITSTATUS(status) : -1, read_file(log)};
}

std::string tetra() { return std::string(RAYPACK_SOURCE_DIR) + "/scenes/tetra.nff"; }

bool loads_openimageio(const std::string& loader_log) { return loader_log.find("libOpenImageIO") != std::string::npos; }

TEST(ImageModule, CommandsThatWriteNoImageNeverLoadOpenImageIO) {
    const fs::path dir = temp_dir();
    for (const std::string& args : {"info " + tetra(), std::string("--help"), "gen balls --size 1 -o " + (dir / "b.nff").string()}) {
        const Outcome r = run_cli(dir, "LD_DEBUG=libs", args);
        EXPECT_EQ(r.status, 0) << args << "\n" << r.log;
        EXPECT_FALSE(loads_openimageio(r.log)) << args;
    }
    // The control: the same probe sees OpenImageIO when an image is written.
    const Outcome r = run_cli(dir, "LD_DEBUG=libs", "render " + tetra() + " --res 8 8 -o " + (dir / "t.png").string());
    EXPECT_EQ(r.status, 0) << r.log;
    EXPECT_TRUE(loads_openimageio(r.log));
    EXPECT_NE(r.log.find("libraypack_image.so"), std::string::npos);
    EXPECT_TRUE(fs::exists(dir / "t.png"));
}

/// Renders with RAYPACK_IMAGE_MODULE=module over an existing output file:
/// the command must fail, say why (with `reason` from the dynamic loader), and
/// leave the file as it was.
void expect_clear_failure(const std::string& module, const std::string& reason) {
    const fs::path dir = temp_dir() / "out";
    fs::create_directories(dir);
    const fs::path out = dir / "keep.png";
    std::ofstream(out) << "previous contents";
    const Outcome r = run_cli(dir, "RAYPACK_IMAGE_MODULE=" + module, "render " + tetra() + " --res 8 8 -o " + out.string());
    EXPECT_EQ(r.status, 1) << r.log;
    EXPECT_NE(r.log.find("image module " + module), std::string::npos) << r.log;
    EXPECT_NE(r.log.find(reason), std::string::npos) << r.log;
    EXPECT_EQ(read_file(out), "previous contents");
    for (const auto& entry : fs::directory_iterator(dir))
        EXPECT_TRUE(entry.path().filename() == "keep.png" || entry.path().filename() == "log.txt") << entry.path();
}

TEST(ImageModule, MissingModuleIsAClearError) {
    expect_clear_failure((temp_dir() / "no_such_module.so").string(), "cannot open shared object file");
}

TEST(ImageModule, FileThatIsNoLibraryIsAClearError) {
    const fs::path fake = temp_dir() / "not_a_library.so";
    std::ofstream(fake) << "this is text, not ELF, and long enough to have a header to read\n";
    expect_clear_failure(fake.string(), "invalid ELF header");
}

TEST(ImageModule, LibraryWithoutTheModuleSymbolIsAClearError) {
    // libm loads, but exports no raypack_image_module.
    expect_clear_failure("libm.so.6", "undefined symbol: raypack_image_module");
}

}  // namespace
}  // namespace raypack
