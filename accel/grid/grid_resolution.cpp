#include <algorithm>
#include <cmath>

#include "accel/grid/grid.h"

namespace raypack {

std::array<int, 3> grid_resolution(const Vec3f& extent, std::size_t n, float lambda, std::size_t max_cells) {
    std::array<int, 3> res{1, 1, 1};
    max_cells = std::max<std::size_t>(max_cells, 1);
    const double target = std::clamp(double(lambda) * double(n), 1.0, double(max_cells));
    if (!(target > 1.0)) return res;
    // Cells of side s: e_a / s cells along each axis, (prod e_a) / s^d in all
    // over the d axes that get more than one cell. An axis thinner than one
    // cell gets exactly one and leaves the product, then s is recomputed.
    std::array<bool, 3> active{};
    for (int a = 0; a < 3; ++a) active[a] = std::isfinite(extent[a]) && extent[a] > 0;
    double side = 0;
    for (int pass = 0; pass < 3; ++pass) {
        int d = 0;
        double volume = 1;
        for (int a = 0; a < 3; ++a) {
            if (!active[a]) continue;
            ++d;
            volume *= double(extent[a]);
        }
        if (d == 0 || !(volume > 0)) return res;
        side = std::pow(volume / target, 1.0 / d);
        bool changed = false;
        for (int a = 0; a < 3; ++a) {
            if (active[a] && double(extent[a]) < side) {
                active[a] = false;
                changed = true;
            }
        }
        if (!changed) break;
    }
    if (!(side > 0)) return res;
    auto total = [&] { return std::size_t(res[0]) * std::size_t(res[1]) * std::size_t(res[2]); };
    for (int a = 0; a < 3; ++a) {
        if (!active[a]) continue;
        const double cells = std::round(double(extent[a]) / side);
        res[a] = int(std::clamp(cells, 1.0, double(max_cells)));
    }
    // Rounding up on every axis can overshoot the cap: trim the longest axis.
    while (total() > max_cells) {
        int* longest = std::max_element(res.begin(), res.end());
        *longest = std::max(1, int(double(*longest) * 0.95));
    }
    return res;
}

}  // namespace raypack
