#pragma once
// Rows of `raypack bench --tradeoff` and their table, JSON and CSV forms.
#include <cstdio>
#include <optional>
#include <string>
#include <vector>

#include "measure/accuracy_measures.h"

namespace raypack::app {

/// Where the mixed scene of the self-intersection measure sits.
struct Placement {
    float scale = 1;
    float translation = 0;  ///< added to every coordinate
};
/// Scales 1e-4, 1e-2, 1, 1e2, 1e4, 1e6 at the origin, then scale 1 moved by 1e6.
const std::vector<Placement>& self_intersection_placements();
/// "s1e-04", "t1e+06": the suffix of the CSV columns of a placement.
std::string placement_label(const Placement& where);

struct TradeoffRow {
    std::string family;   ///< triangle | sphere | slabs | rcp | precision | builder | offset
    std::string variant;  ///< moeller, watertight, ... | epsilon, scaled, robust | plain, robust | ...
    // Throughput: Mrays/s over `repeat` timed passes.
    std::string throughput_scene, throughput_rays;
    std::size_t timed_rays = 0;
    int repeat = 0;
    double mrays_per_s_median = 0, mrays_per_s_min = 0, mrays_per_s_max = 0;
    std::optional<LeakCounts> leaks;
    std::optional<UlpError> t_ulps;
    std::vector<SelfIntersections> self;  ///< empty, or one per self_intersection_placements()
    /// Offset rows: the image scene placed as each self_intersection_placements()
    /// entry against the unplaced one, same policy (measure/scale_invariance.h).
    std::vector<ImageError> placed_image;
    std::string image_scene;
    int image_width = 0, image_height = 0;
    std::optional<ImageError> image;
    // Where every figure of the row comes from.
    std::string structure;  ///< bvh2 | bvh8
    std::string builder;    ///< binned | sweep | morton | sbvh
    std::string kernels;    ///< kernel_choice_summary()
    std::optional<double> build_ms, sah_cost;  ///< builder family: of the throughput scene's structure
};

void print_tradeoff_table(std::FILE* out, const std::vector<TradeoffRow>& rows);
/// Written atomically; throw std::runtime_error naming the file on failure.
void write_tradeoff_json(const std::string& path, const std::vector<TradeoffRow>& rows);
void write_tradeoff_csv(const std::string& path, const std::vector<TradeoffRow>& rows);

}  // namespace raypack::app
