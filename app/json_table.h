#pragma once
// Rows as JSON objects, written as a JSON array or as CSV with the objects'
// keys as columns (the first row's order); both atomically.
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

namespace raypack::app {

/// Throws std::runtime_error naming `path` when it cannot be written.
void write_text_atomically(const std::string& path, const std::string& text);
void write_json_rows(const std::string& path, const std::vector<nlohmann::ordered_json>& rows);
/// `columns`: an object whose keys name the columns (values ignored), so that
/// an empty table still has its header. Names hold no commas or quotes;
/// values that do are quoted (RFC 4180).
void write_csv_rows(const std::string& path, const nlohmann::ordered_json& columns,
                    const std::vector<nlohmann::ordered_json>& rows);

}  // namespace raypack::app
