#include "measure/cost_map.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <atomic>
#include <stdexcept>

#include "measure/colormap.h"
#include "measure/digit_font.h"
#include "measure/ray_sets.h"

namespace raypack {
namespace {

int legend_scale(int width) { return width >= 256 ? 2 : 1; }

}  // namespace

CostMap primary_ray_cost(const Scene& scene, const Accel& accel, int width, int height) {
    CostMap map;
    map.width = width;
    map.height = height;
    const std::vector<Rayf> rays = camera_ray_set(scene, width, height);
    map.cost.resize(rays.size());
    map.hit.resize(rays.size());
    std::atomic<bool> counted{true};
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, rays.size(), 256), [&](const auto& r) {
        for (std::size_t i = r.begin(); i < r.end(); ++i) {
            TraversalCounts c;
            Hitf hit;
            if (!accel.count_traversal({&rays[i], 1}, false, {&hit, 1}, c)) {
                counted = false;
                return;
            }
            map.cost[i] = std::uint32_t(std::min<std::uint64_t>(c.nodes + c.prims, 0xFFFFFFFFu));
            map.hit[i] = hit.found() ? 1 : 0;
        }
    });
    if (!counted && !scene.moving_instances.empty())
        throw std::runtime_error("traversal costs are not counted for scenes with motion (the motion BVH does not count)");
    if (!counted)
        throw std::runtime_error(accel.stats().name + " cannot count its traversal steps; choose another structure");
    if (!map.cost.empty()) {
        const auto [lo, hi] = std::minmax_element(map.cost.begin(), map.cost.end());
        map.min = *lo;
        map.max = *hi;
    }
    return map;
}

int cost_legend_height(int width) { return 4 + 8 + 2 + 5 * legend_scale(width) + 4; }

Image cost_heat_map(const CostMap& map) {
    const int legend = cost_legend_height(map.width);
    Image image(map.width, map.height + legend);
    const float range = float(std::max<std::uint32_t>(1, map.max - map.min));
    for (int y = 0; y < map.height; ++y)
        for (int x = 0; x < map.width; ++x) {
            const std::uint32_t c = map.cost[std::size_t(y) * std::size_t(map.width) + std::size_t(x)];
            image.set(x, y, viridis(float(c - map.min) / range));
        }
    // The scale: a bar from min to max, min labelled at its left end, max at its right.
    const int margin = 4, bar_top = map.height + 4, bar_width = std::max(1, map.width - 2 * margin);
    for (int x = 0; x < bar_width; ++x) {
        const Vec3f colour = viridis(bar_width > 1 ? float(x) / float(bar_width - 1) : 0.0f);
        for (int y = bar_top; y < bar_top + 8; ++y)
            if (margin + x < map.width) image.set(margin + x, y, colour);
    }
    const int scale = legend_scale(map.width), text_top = bar_top + 8 + 2;
    const std::string lo = std::to_string(map.min), hi = std::to_string(map.max);
    const Vec3f white(1.0f, 1.0f, 1.0f);
    draw_text(image, margin, text_top, lo, scale, white);
    draw_text(image, map.width - margin - text_width(hi, scale), text_top, hi, scale, white);
    return image;
}

}  // namespace raypack
