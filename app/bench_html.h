#pragma once
// `raypack bench --report out.html`: one self-contained HTML file (no
// network, no files beside it) with the run's tables, a bar chart per scene
// and ray kind (inline SVG), the camera rays' cost heat maps (BMP data
// URIs) and Havran's measures beside Havran and Sixta's 1999 figures for
// the SPD scenes. Written atomically.
#include <string>
#include <vector>

#include "app/bench_row.h"
#include "render/image.h"

namespace raypack::app {

/// One structure's camera-ray cost heat map on one scene (measure/cost_map.h).
struct CostMapPicture {
    std::string scene, accel;
    Image image;
};

struct BenchHtmlContext {
    std::string command;  ///< the command line that made the run
    std::string machine;  ///< the processor, as /proc/cpuinfo names it
    std::vector<CostMapPicture> maps;
};

void write_bench_html(const std::string& path, const std::vector<BenchRow>& rows, const BenchHtmlContext& context);

/// The processor's model name from /proc/cpuinfo, or "unknown".
std::string processor_name();

/// `image` (values clamped to [0, 1]) as an uncompressed 24-bit BMP file.
std::string bmp_bytes(const Image& image);

}  // namespace raypack::app
