#include "tests/test_paths.h"

namespace raypack::test {
const char* source_dir() { return RAYPACK_SOURCE_DIR_VALUE; }
const char* cli_path() { return RAYPACK_CLI_VALUE; }
}  // namespace raypack::test
