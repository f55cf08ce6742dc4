#pragma once
// Write-to-temporary-then-rename, so that an existing output is replaced
// whole or not at all.
#include <functional>
#include <string>

namespace raypack {

/// Calls `write(tmp_path)` with a fresh path in the same directory as `path`,
/// then renames it over `path`. If `write` throws, the temporary is removed
/// and the exception propagates; `path` is untouched.
void write_atomically(const std::string& path, const std::function<void(const std::string& tmp_path)>& write);

}  // namespace raypack
