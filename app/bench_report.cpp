#include "app/bench_report.h"

#include <nlohmann/json.hpp>
#include <stdexcept>

#include "app/json_table.h"

namespace raypack::app {
namespace {

std::string format_optional(const std::optional<double>& v, const char* format) {
    if (!v) return "-";
    char buf[32];
    std::snprintf(buf, sizeof buf, format, *v);
    return buf;
}

std::string format_bytes(std::size_t bytes) {
    char buf[32];
    if (bytes >= (std::size_t(1) << 20)) std::snprintf(buf, sizeof buf, "%.1f MiB", double(bytes) / double(1 << 20));
    else std::snprintf(buf, sizeof buf, "%.1f KiB", double(bytes) / 1024.0);
    return buf;
}

/// Column order of the JSON objects and the CSV file.
nlohmann::ordered_json to_json(const BenchRow& r) {
    nlohmann::ordered_json j;
    j["scene"] = r.scene;
    j["scene_file"] = r.scene_file;
    j["accel"] = r.accel;
    j["builder"] = r.builder;
    j["packet"] = r.packet;
    j["rays"] = r.rays;
    j["query"] = r.any_hit ? "any" : "closest";
    j["ray_count"] = r.ray_count;
    j["threads"] = r.threads;
    j["repeat"] = r.repeat;
    j["build_ms"] = r.build_ms;
    j["memory_bytes"] = r.memory_bytes;
    j["sah_cost"] = r.sah_cost;
    j["mrays_per_s_median"] = r.mrays_per_s_median;
    j["mrays_per_s_min"] = r.mrays_per_s_min;
    j["mrays_per_s_max"] = r.mrays_per_s_max;
    j["trace_ms_median"] = r.trace_ms_median;
    for (const auto& [name, value] : {std::pair{"n_it", r.n_it}, {"n_ts", r.n_ts}, {"n_ets", r.n_ets}, {"n_eets", r.n_eets}})
        j[name] = value ? nlohmann::ordered_json(*value) : nlohmann::ordered_json();
    j["hits"] = r.hits;
    j["validated_rays"] = r.validated_rays;
    j["validated"] = r.validated;
    return j;
}

}  // namespace

void print_bench_header(std::FILE* out) {
    std::fprintf(out, "%-8s %-7s %2s %-8s %3s %9s %10s %9s %9s %19s %7s %7s %7s %7s\n", "scene", "accel", "K", "rays",
                 "thr", "build ms", "memory", "SAH cost", "Mrays/s", "(min - max)", "N_IT", "N_TS", "N_ETS", "N_EETS");
}

void print_bench_row(std::FILE* out, const BenchRow& r) {
    char spread[32];
    std::snprintf(spread, sizeof spread, "(%.2f - %.2f)", r.mrays_per_s_min, r.mrays_per_s_max);
    std::fprintf(out, "%-8s %-7s %2d %-8s %3d %9.1f %10s %9s %9.2f %19s %7s %7s %7s %7s\n", r.scene.c_str(),
                 r.accel.c_str(), r.packet, r.rays.c_str(), r.threads, r.build_ms, format_bytes(r.memory_bytes).c_str(),
                 r.sah_cost > 0 ? format_optional(r.sah_cost, "%.1f").c_str() : "-", r.mrays_per_s_median, spread,
                 format_optional(r.n_it, "%.1f").c_str(), format_optional(r.n_ts, "%.1f").c_str(),
                 format_optional(r.n_ets, "%.1f").c_str(), format_optional(r.n_eets, "%.2f").c_str());
}

void write_bench_json(const std::string& path, const std::vector<BenchRow>& rows) {
    std::vector<nlohmann::ordered_json> objects;
    for (const BenchRow& r : rows) objects.push_back(to_json(r));
    write_json_rows(path, objects);
}

void write_bench_csv(const std::string& path, const std::vector<BenchRow>& rows) {
    std::vector<nlohmann::ordered_json> objects;
    for (const BenchRow& r : rows) objects.push_back(to_json(r));
    write_csv_rows(path, to_json(BenchRow{}), objects);
}

}  // namespace raypack::app
