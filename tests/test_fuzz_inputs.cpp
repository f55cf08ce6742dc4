// The fuzzers' seeds and every input that ever made a fuzzer fail
// (fuzz/regressions/TARGET/, kept once fixed), replayed through the same
// parsers in the normal build: each must end in a result or a clean error.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <stdexcept>
#include <string>

#include "scene/load.h"
#include "scene/nff_text.h"
#include "scene/ray_file.h"
#include "tests/temp_dir_test.h"
#include "tests/test_paths.h"

namespace raypack {
namespace {

namespace fs = std::filesystem;

/// Files of fuzz/seeds/TARGET and fuzz/regressions/TARGET.
std::vector<fs::path> inputs(const std::string& target) {
    std::vector<fs::path> out;
    for (const char* kind : {"seeds", "regressions"}) {
        const fs::path dir = fs::path(RAYPACK_SOURCE_DIR) / "fuzz" / kind / target;
        if (fs::is_directory(dir))
            for (const auto& e : fs::directory_iterator(dir)) out.push_back(e.path());
    }
    return out;
}

class FuzzInputs : public TempDirTest {};

TEST_F(FuzzInputs, NffAndObjInputsLoadOrFailCleanly) {
    const auto nff = inputs("nff"), obj = inputs("obj");
    ASSERT_FALSE(nff.empty());
    ASSERT_FALSE(obj.empty());
    for (const fs::path& p : nff) {
        try {
            load_nff_text(file_bytes(p), p.string());
        } catch (const SceneError&) {
        }
    }
    for (const fs::path& p : obj) {
        try {
            load_obj_file(p.string());
        } catch (const SceneError&) {
        }
    }
}

TEST_F(FuzzInputs, RayAndHitInputsLoadOrFailCleanly) {
    const auto rays = inputs("rays");
    ASSERT_FALSE(rays.empty());
    for (const fs::path& p : rays) {
        // As the fuzzer reads them: the first byte picks the reader.
        const std::string bytes = file_bytes(p);
        if (bytes.empty()) continue;
        const fs::path body = dir_ / "body.bin";
        std::ofstream(body, std::ios::binary) << bytes.substr(1);
        try {
            if (bytes[0] & 1) read_hits(body.string());
            else read_rays(body.string());
        } catch (const std::runtime_error&) {
        }
    }
}

}  // namespace
}  // namespace raypack
