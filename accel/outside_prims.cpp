#include "accel/outside_prims.h"

#include <algorithm>

namespace raypack {
namespace {

bool usable(const Box3f& b) { return all_finite(b.lo) && all_finite(b.hi) && !b.empty(); }

}  // namespace

std::vector<std::uint32_t> large_primitives(std::span<const Box3f> boxes) {
    // The largest kMaxOutside usable boxes, largest first.
    std::vector<std::uint32_t> top;
    std::size_t usable_count = 0;
    auto larger = [&](std::uint32_t a, std::uint32_t b) { return boxes[a].half_area() > boxes[b].half_area(); };
    for (std::uint32_t p = 0; p < boxes.size(); ++p) {
        if (!usable(boxes[p])) continue;
        ++usable_count;
        if (top.size() < kMaxOutside + 1) {
            top.push_back(p);
            std::push_heap(top.begin(), top.end(), [&](auto a, auto b) { return larger(a, b); });
        } else if (larger(p, top.front())) {
            std::pop_heap(top.begin(), top.end(), [&](auto a, auto b) { return larger(a, b); });
            top.back() = p;
            std::push_heap(top.begin(), top.end(), [&](auto a, auto b) { return larger(a, b); });
        }
    }
    if (usable_count < kMinPrimitives) return {};
    std::sort(top.begin(), top.end(), [&](auto a, auto b) { return larger(a, b) || (!larger(b, a) && a < b); });
    top.resize(kMaxOutside);
    // rest[m]: the box of every usable primitive but the m largest.
    std::vector<bool> in_top(boxes.size(), false);
    for (std::uint32_t p : top) in_top[p] = true;
    Box3f rest[kMaxOutside + 1];
    for (std::uint32_t p = 0; p < boxes.size(); ++p)
        if (usable(boxes[p]) && !in_top[p]) rest[kMaxOutside].extend(boxes[p]);
    for (std::size_t m = kMaxOutside; m-- > 0;) {
        rest[m] = rest[m + 1];
        rest[m].extend(boxes[top[m]]);
    }
    const float all = rest[0].half_area();
    float best = 1.0f;
    float shrink[kMaxOutside + 1];
    for (std::size_t m = 0; m <= kMaxOutside; ++m) {
        const float a = rest[m].half_area();
        shrink[m] = a > 0.0f ? all / a : 1.0f;  // a flat or empty rest: no measure of gain
        best = std::max(best, shrink[m]);
    }
    if (best < kMinShrink) return {};
    std::size_t m = 1;
    while (shrink[m] < 0.8f * best) ++m;
    top.resize(m);
    std::sort(top.begin(), top.end());
    return top;
}

std::vector<std::uint32_t> take_large_primitives(std::span<Box3f> boxes) {
    std::vector<std::uint32_t> outside = large_primitives(boxes);
    for (std::uint32_t p : outside) boxes[p] = Box3f{};  // an empty box: in no cell
    return outside;
}

}  // namespace raypack
