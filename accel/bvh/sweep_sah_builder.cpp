#include "accel/bvh/sweep_sah_builder.h"

#include <algorithm>
#include <array>
#include <numeric>
#include <vector>

#include "accel/bvh/bvh2_finalize.h"

namespace raypack {
namespace {

class SweepBuilder {
public:
    SweepBuilder(std::span<const Box3f> boxes, const BvhBuildConfig& config)
        : boxes_(boxes), rule_(config), right_weighted_(boxes.size() + 1), is_left_(boxes.size()), tmp_(boxes.size()) {
        const std::size_t n = boxes.size();
        std::vector<Vec3f> centers(n);
        for (std::size_t i = 0; i < n; ++i) centers[i] = boxes[i].center();
        for (int a = 0; a < 3; ++a) {
            order_[a].resize(n);
            std::iota(order_[a].begin(), order_[a].end(), 0u);
            // Ties broken by primitive number: the tree does not depend on the sort.
            std::sort(order_[a].begin(), order_[a].end(), [&](std::uint32_t p, std::uint32_t q) {
                return centers[p][a] < centers[q][a] || (centers[p][a] == centers[q][a] && p < q);
            });
        }
        nodes_.reserve(2 * n);
    }

    Bvh2 run() {
        build(0, std::uint32_t(boxes_.size()), 1);
        return finalize_bvh2(nodes_, std::move(order_[0]));
    }

private:
    std::span<const Box3f> boxes_;
    SahRule rule_;
    std::array<std::vector<std::uint32_t>, 3> order_;
    std::vector<Bvh2Node> nodes_;
    std::vector<float> right_weighted_;      // scratch: area * count of the suffix from i
    std::vector<std::uint8_t> is_left_;     // scratch: side of each primitive
    std::vector<std::uint32_t> tmp_;        // scratch: stable partition

    void build(std::uint32_t begin, std::uint32_t end, int depth) {
        const std::uint32_t node = std::uint32_t(nodes_.size());
        nodes_.push_back({});
        const std::uint32_t n = end - begin;
        Box3f box;
        for (std::uint32_t i = begin; i < end; ++i) box.extend(boxes_[order_[0][i]]);
        nodes_[node] = {box, begin, n};
        if (n == 1 || depth >= kBvhMaxDepth) return;

        // Sweep each axis from the right, then from the left.
        const float inv_area = 1.0f / std::max(box.half_area(), std::numeric_limits<float>::min());
        int best_axis = -1;
        std::uint32_t best_mid = 0;
        float best_cost = std::numeric_limits<float>::infinity();
        for (int a = 0; a < 3; ++a) {
            const std::uint32_t* ord = order_[a].data();
            Box3f acc;
            for (std::uint32_t i = end - 1; i > begin; --i) {
                acc.extend(boxes_[ord[i]]);
                right_weighted_[i - begin] = acc.half_area() * float(end - i);
            }
            acc = Box3f{};
            for (std::uint32_t i = begin + 1; i < end; ++i) {
                acc.extend(boxes_[ord[i - 1]]);
                const float cost = rule_.split_cost(acc.half_area() * float(i - begin) + right_weighted_[i - begin], inv_area);
                if (cost < best_cost) best_cost = cost, best_axis = a, best_mid = i;
            }
        }
        if (rule_.prefers_leaf(n, best_cost)) return;

        // Keep the three orders sorted on both sides: a stable partition by side.
        for (std::uint32_t i = begin; i < end; ++i) is_left_[order_[best_axis][i]] = i < best_mid;
        for (int a = 0; a < 3; ++a) {
            if (a == best_axis) continue;
            std::uint32_t* ord = order_[a].data();
            std::uint32_t l = begin, r = 0;
            for (std::uint32_t i = begin; i < end; ++i) {
                if (is_left_[ord[i]]) ord[l++] = ord[i];
                else tmp_[r++] = ord[i];
            }
            std::copy_n(tmp_.begin(), r, ord + l);
        }
        build(begin, best_mid, depth + 1);
        nodes_[node].first = std::uint32_t(nodes_.size());
        nodes_[node].count = 0;
        build(best_mid, end, depth + 1);
    }
};

}  // namespace

Bvh2 build_sweep_sah(std::span<const Box3f> boxes, const BvhBuildConfig& config) {
    if (boxes.empty()) return {};
    return SweepBuilder(boxes, config).run();
}

}  // namespace raypack
