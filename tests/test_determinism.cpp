// The same command writes byte-identical files whatever the thread count
// (1, 2, 7) and packet width: images of every integrator (a sampled one's
// random numbers depend on the pixel and sample, not the thread), ray files
// and hit files. Through the command line, as a user would run it.
#include <gtest/gtest.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include <unistd.h>

#include "kernels/simd.h"
#include "tests/temp_dir_test.h"
#include "tests/test_paths.h"

namespace {

namespace fs = std::filesystem;

class Determinism : public TempDirTest {
protected:
    /// Runs `raypack ARGS -o FILE` for each variant of `extra` and expects
    /// every output to equal the first, byte for byte.
    void expect_same_output(const std::string& args, const std::string& ext, const std::vector<std::string>& extra) {
        std::string first;
        for (std::size_t i = 0; i < extra.size(); ++i) {
            const fs::path out = dir_ / ("out" + std::to_string(i) + ext);
            const std::string cmd = std::string(RAYPACK_CLI) + " " + args + " " + extra[i] + " -o " + out.string() +
                                    " > /dev/null 2>&1";
            ASSERT_EQ(std::system(cmd.c_str()), 0) << cmd;
            const std::string bytes = file_bytes(out);
            ASSERT_FALSE(bytes.empty()) << cmd;
            if (i == 0) first = bytes;
            else EXPECT_TRUE(bytes == first) << "differs from the first run: " << cmd;
        }
    }
};

const std::vector<std::string> kThreadsAndWidths = {"--threads 1", "--threads 2", "--threads 7",
                                                    "--threads 2 --accel bvh4 --packet 1",
                                                    "--threads 7 --accel bvh4 --packet 8"};

TEST_F(Determinism, WhittedImages) {
    expect_same_output("render gen:gears:2 --res 96 72", ".png", kThreadsAndWidths);
}

TEST_F(Determinism, DistributionImages) {
    expect_same_output("render gen:cornell:2 --res 64 64 --integrator distribution --spp 8 --light-samples 2 "
                       "--sampler sobol --filter tent",
                       ".exr", kThreadsAndWidths);
}

TEST_F(Determinism, AdaptiveImages) {
    expect_same_output("render gen:balls:2:area-lights+lens --res 64 64 --integrator distribution --adaptive 0.1",
                       ".exr", kThreadsAndWidths);
}

TEST_F(Determinism, PathImages) {
    expect_same_output("render gen:cornell:2 --res 48 48 --integrator path --spp 4 --depth 6", ".exr",
                       kThreadsAndWidths);
}

TEST_F(Determinism, RayAndHitFiles) {
    const std::string scene = "gen:balls:3";
    // The widest packets this build has (16 needs AVX-512).
    const std::string widest = "--threads 7 --accel bvh8 --packet " + std::to_string(raypack::kWidthCompiled<16> ? 16 : 8);
    for (const char* kind : {"camera", "shadow", "diffuse"}) {
        SCOPED_TRACE(kind);
        expect_same_output("rays " + scene + " --kind " + std::string(kind) + " --res 64 64", ".rays",
                           {"", "", ""});
        const fs::path rays = dir_ / "out0.rays";
        const fs::path keep = dir_ / (std::string(kind) + ".rays");
        fs::rename(rays, keep);
        expect_same_output("trace " + scene + " --rays " + keep.string() + " --repeat 1", ".hits",
                           {"--threads 1", "--threads 2", "--threads 7", widest,
                            "--threads 2 --accel bvh2 --packet 1"});
    }
}

}  // namespace
