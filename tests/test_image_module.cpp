// The image modules (libraypack_image.so, libraypack_png.so;
// render/image_module.h): commands that write no image load neither, a PNG
// is written without OpenImageIO but with the same pixels, and a missing or
// broken module is a clear error with a non-zero status, never a crash or an
// output file.
#include <gtest/gtest.h>
#include <sys/wait.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include "render/image.h"
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
    // The controls: the same probe sees OpenImageIO when an EXR is written,
    // and libpng alone when a PNG is.
    const Outcome exr = run_cli(dir, "LD_DEBUG=libs", "render " + tetra() + " --res 8 8 -o " + (dir / "t.exr").string());
    EXPECT_EQ(exr.status, 0) << exr.log;
    EXPECT_TRUE(loads_openimageio(exr.log));
    EXPECT_NE(exr.log.find("libraypack_image.so"), std::string::npos);
    EXPECT_TRUE(fs::exists(dir / "t.exr"));
    const Outcome png = run_cli(dir, "LD_DEBUG=libs", "render " + tetra() + " --res 8 8 -o " + (dir / "t.png").string());
    EXPECT_EQ(png.status, 0) << png.log;
    EXPECT_FALSE(loads_openimageio(png.log));
    EXPECT_NE(png.log.find("libpng16"), std::string::npos);
    EXPECT_TRUE(fs::exists(dir / "t.png"));
}

TEST(ImageModule, PngModuleWritesTheBytesOpenImageIOWrites) {
    // Every rounding threshold (k + 0.5) / 255 and every k / 255, with the
    // 8 floats on each side: both conversions are monotone, so agreeing
    // there is agreeing everywhere. Also values outside [0, 1] (clamped).
    std::vector<float> values = {-1.0f, -0.0f, 1.5f, 1e30f};
    for (int k = 0; k < 256; ++k)
        for (const float centre : {float(k) / 255.0f, (float(k) + 0.5f) / 255.0f}) {
            float v = centre;
            for (int i = 0; i < 8; ++i) v = std::nextafter(v, -1.0f);
            for (int i = 0; i < 17; ++i, v = std::nextafter(v, 2.0f)) values.push_back(v);
        }
    const int width = 64, height = int((values.size() + 3 * 64 - 1) / (3 * 64));
    Image image(width, height);
    std::copy(values.begin(), values.end(), image.rgb.begin());
    const fs::path dir = temp_dir();
    write_image((dir / "libpng.png").string(), image);    // libraypack_png.so
    write_image((dir / "oiio.tif").string(), image);      // libraypack_image.so, also 8 bits
    const Image png = read_image((dir / "libpng.png").string()), tif = read_image((dir / "oiio.tif").string());
    ASSERT_EQ(png.width, width);
    ASSERT_EQ(png.height, height);
    EXPECT_EQ(png.rgb, tif.rgb);
    EXPECT_EQ(png.at(0, 0), Vec3f(0.0f, 0.0f, 1.0f));  // -1, -0 and 1.5 clamped
}

/// Renders to `output_name` with `variable`=module over an existing output
/// file: the command must fail, say why (with `reason` from the dynamic
/// loader), and leave the file as it was.
void expect_clear_failure(const std::string& variable, const std::string& module, const std::string& output_name,
                          const std::string& reason) {
    const fs::path dir = temp_dir() / ("out_" + variable);
    fs::remove_all(dir);
    fs::create_directories(dir);
    const fs::path out = dir / output_name;
    std::ofstream(out) << "previous contents";
    const Outcome r = run_cli(dir, variable + "=" + module, "render " + tetra() + " --res 8 8 -o " + out.string());
    EXPECT_EQ(r.status, 1) << r.log;
    EXPECT_NE(r.log.find("image module " + module), std::string::npos) << r.log;
    EXPECT_NE(r.log.find(reason), std::string::npos) << r.log;
    EXPECT_EQ(read_file(out), "previous contents");
    for (const auto& entry : fs::directory_iterator(dir))
        EXPECT_TRUE(entry.path().filename() == output_name || entry.path().filename() == "log.txt") << entry.path();
}

TEST(ImageModule, MissingModuleIsAClearError) {
    const std::string missing = (temp_dir() / "no_such_module.so").string();
    expect_clear_failure("RAYPACK_IMAGE_MODULE", missing, "keep.exr", "cannot open shared object file");
    expect_clear_failure("RAYPACK_PNG_MODULE", missing, "keep.png", "cannot open shared object file");
}

TEST(ImageModule, FileThatIsNoLibraryIsAClearError) {
    const fs::path fake = temp_dir() / "not_a_library.so";
    std::ofstream(fake) << "this is text, not ELF, and long enough to have a header to read\n";
    expect_clear_failure("RAYPACK_IMAGE_MODULE", fake.string(), "keep.exr", "invalid ELF header");
}

TEST(ImageModule, LibraryWithoutTheModuleSymbolIsAClearError) {
    // libm loads, but exports no raypack_image_module.
    expect_clear_failure("RAYPACK_PNG_MODULE", "libm.so.6", "keep.png", "undefined symbol: raypack_image_module");
}

}  // namespace
}  // namespace raypack
