#pragma once
// A test fixture for the scene loaders' tests: files written into a
// temporary folder of the test's own, loaded, and expected errors checked.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>
#include <utility>
#include <unistd.h>

#include "scene/load.h"

/// Each test writes its files into its own temporary folder (per process and
/// test, since test runs may overlap) and removes it afterwards.
class SceneFiles : public ::testing::Test {
protected:
    using Loader = raypack::Scene (*)(const std::string&);
    /// Files given to load() and expect_error() end in `extension` and are
    /// read by `loader`.
    SceneFiles(Loader loader, std::string extension) : loader_(loader), extension_(std::move(extension)) {}

    void SetUp() override {
        dir_ = std::filesystem::temp_directory_path() /
               ("raypack_scene_" + std::to_string(::getpid()) + "_" +
                ::testing::UnitTest::GetInstance()->current_test_info()->name());
        std::filesystem::create_directories(dir_);
    }
    void TearDown() override {
        std::error_code ec;
        std::filesystem::remove_all(dir_, ec);
    }

    std::string write(const std::string& name, const std::string& text) {
        const std::string path = (dir_ / name).string();
        std::ofstream(path, std::ios::binary) << text;
        return path;
    }

    raypack::Scene load(const std::string& text) { return loader_(write("scene" + extension_, text)); }

    /// Loading `text` fails with a SceneError naming the file, `line` and `phrase`.
    void expect_error(const std::string& text, int line, const std::string& phrase) {
        const std::string path = write("bad" + extension_, text);
        try {
            loader_(path);
            ADD_FAILURE() << "no error for:\n" << text;
        } catch (const raypack::SceneError& e) {
            EXPECT_EQ(e.file(), path);
            EXPECT_EQ(e.line(), line) << e.what();
            EXPECT_NE(e.problem().find(phrase), std::string::npos) << e.what();
            const std::string prefix = path + ":" + std::to_string(line) + ": ";
            EXPECT_EQ(std::string(e.what()).rfind(prefix, 0), 0u) << e.what();
        }
    }

    Loader loader_;
    std::string extension_;
    std::filesystem::path dir_;
};

