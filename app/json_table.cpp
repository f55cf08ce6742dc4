#include "app/json_table.h"

#include <fstream>
#include <sstream>
#include <stdexcept>

#include "scene/atomic_file.h"

namespace raypack::app {
namespace {

/// RFC 4180: a text holding a comma, quote or line break goes in quotes,
/// its quotes doubled (kernel summaries are comma-separated lists).
std::string csv_field(const nlohmann::ordered_json& v) {
    if (v.is_null()) return "";
    if (!v.is_string()) return v.dump();
    const std::string text = v.get<std::string>();
    if (text.find_first_of(",\"\r\n") == std::string::npos) return text;
    std::string quoted = "\"";
    for (char c : text) quoted += c == '"' ? std::string("\"\"") : std::string(1, c);
    return quoted + "\"";
}

}  // namespace

void write_text_atomically(const std::string& path, const std::string& text) {
    write_atomically(path, [&](const std::string& tmp) {
        std::ofstream out(tmp, std::ios::binary);
        out << text;
        out.close();
        if (!out) throw std::runtime_error("cannot write " + path);
    });
}

void write_json_rows(const std::string& path, const std::vector<nlohmann::ordered_json>& rows) {
    nlohmann::ordered_json array = nlohmann::ordered_json::array();
    for (const auto& r : rows) array.push_back(r);
    write_text_atomically(path, array.dump(2) + "\n");
}

void write_csv_rows(const std::string& path, const nlohmann::ordered_json& columns,
                    const std::vector<nlohmann::ordered_json>& rows) {
    std::ostringstream out;
    bool first = true;
    for (const auto& key_value : columns.items()) {
        out << (first ? "" : ",") << key_value.key();
        first = false;
    }
    out << "\n";
    for (const auto& row : rows) {
        first = true;
        for (const auto& key_value : columns.items()) {
            out << (first ? "" : ",") << csv_field(row.value(key_value.key(), nlohmann::ordered_json()));
            first = false;
        }
        out << "\n";
    }
    write_text_atomically(path, out.str());
}

}  // namespace raypack::app
