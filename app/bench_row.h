#pragma once
// One measured case of `raypack bench`: the row of the table, the JSON array
// and the CSV file (schema in docs/bench.md).
#include <cstddef>
#include <optional>
#include <string>

namespace raypack::app {

struct BenchRow {
    std::string scene;        ///< short name: "balls", "bunny"
    std::string scene_file;   ///< as given: gen:balls:4, scenes/bunny.obj
    std::string accel;
    std::string builder;
    int packet = 1;
    std::string rays;         ///< camera | shadow | diffuse | file:NAME
    bool any_hit = false;
    std::size_t ray_count = 0;
    int threads = 1;
    int repeat = 0;
    double build_ms = 0;
    std::size_t memory_bytes = 0;
    double sah_cost = 0;      ///< the structure's quality figure (0 where it means nothing)
    double mrays_per_s_median = 0, mrays_per_s_min = 0, mrays_per_s_max = 0;
    double trace_ms_median = 0;
    /// Per ray, Havran's measures (accel/traversal_counts.h): intersection
    /// tests, traversal steps, leaves or cells entered, empty ones among
    /// them; empty where the structure cannot count (Embree).
    std::optional<double> n_it, n_ts, n_ets, n_eets;
    std::size_t hits = 0;     ///< closest hits found, or occluded rays
    std::size_t validated_rays = 0;
    bool validated = false;
};

}  // namespace raypack::app
