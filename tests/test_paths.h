#pragma once
// Where the tests find the sources and the raypack executable. Defined in
// test_paths.cpp alone, so that the other test files compile the same in
// every checkout and ccache (base_dir) can share their objects.
namespace raypack::test {
const char* source_dir();
const char* cli_path();
}  // namespace raypack::test

#define RAYPACK_SOURCE_DIR ::raypack::test::source_dir()
#define RAYPACK_CLI ::raypack::test::cli_path()
