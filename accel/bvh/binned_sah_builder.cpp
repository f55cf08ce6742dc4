#include "accel/bvh/binned_sah_builder.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <numeric>

namespace raypack {
namespace {

struct Bin {
    Box3f box;
    std::uint32_t count = 0;
};

struct Split {
    int axis = -1;
    int bin = 0;  // primitives in bins [0, bin) go left
    float cost = std::numeric_limits<float>::infinity();
};

class Builder {
public:
    Builder(std::span<const Box3f> boxes, std::span<const Vec3f> centers, const BinnedSahConfig& config, Bvh2& out)
        : boxes_(boxes), centers_(centers), config_(config), out_(out) {}

    void build() {
        out_.prim_index.resize(boxes_.size());
        std::iota(out_.prim_index.begin(), out_.prim_index.end(), 0u);
        out_.nodes.reserve(2 * boxes_.size());
        out_.nodes.push_back({});
        build_node(0, 0, std::uint32_t(boxes_.size()), 1);
    }

private:
    std::span<const Box3f> boxes_;
    std::span<const Vec3f> centers_;
    const BinnedSahConfig& config_;
    Bvh2& out_;

    void make_leaf(std::uint32_t node, std::uint32_t begin, std::uint32_t end) {
        out_.nodes[node].first = begin;
        out_.nodes[node].count = end - begin;
        ++out_.leaves;
    }

    void build_node(std::uint32_t node, std::uint32_t begin, std::uint32_t end, int depth) {
        out_.depth = std::max(out_.depth, depth);
        std::uint32_t* idx = out_.prim_index.data();
        // Compute bounds of the primitives and of their centres.
        Box3f box, centroid_box;
        for (std::uint32_t i = begin; i < end; ++i) {
            box.extend(boxes_[idx[i]]);
            centroid_box.extend(centers_[idx[i]]);
        }
        out_.nodes[node].box = box;
        const std::uint32_t n = end - begin;
        if (n == 1 || depth >= kBvhMaxDepth) return make_leaf(node, begin, end);

        const Split split = find_split(idx + begin, n, box, centroid_box);
        const float leaf_cost = config_.intersection_cost * float(n);
        std::uint32_t mid;
        if (split.axis < 0) {
            // All centres coincide: SAH cannot separate them.
            if (n <= std::uint32_t(config_.max_leaf_size)) return make_leaf(node, begin, end);
            mid = begin + n / 2;
        } else {
            if (n <= std::uint32_t(config_.max_leaf_size) && leaf_cost <= split.cost)
                return make_leaf(node, begin, end);
            const int axis = split.axis;
            const float lo = centroid_box.lo[axis];
            const float scale = bin_scale(centroid_box, axis);
            std::uint32_t* m = std::partition(idx + begin, idx + end, [&](std::uint32_t p) {
                return bin_of(centers_[p][axis], lo, scale) < split.bin;
            });
            mid = std::uint32_t(m - idx);
            if (mid == begin || mid == end) mid = begin + n / 2;  // cannot happen with a valid split; be safe
        }
        const std::uint32_t left = std::uint32_t(out_.nodes.size());
        out_.nodes.push_back({});
        build_node(left, begin, mid, depth + 1);
        const std::uint32_t right = std::uint32_t(out_.nodes.size());
        out_.nodes.push_back({});
        build_node(right, mid, end, depth + 1);
        out_.nodes[node].first = right;
        out_.nodes[node].count = 0;
    }

    float bin_scale(const Box3f& centroid_box, int axis) const {
        const float extent = centroid_box.hi[axis] - centroid_box.lo[axis];
        return float(config_.bins) / extent;
    }
    int bin_of(float c, float lo, float scale) const {
        return std::clamp(int((c - lo) * scale), 0, config_.bins - 1);
    }

    Split find_split(const std::uint32_t* idx, std::uint32_t n, const Box3f& box, const Box3f& centroid_box) const {
        Split best;
        const float inv_area = 1.0f / std::max(box.half_area(), std::numeric_limits<float>::min());
        std::array<Bin, 256> bins;
        std::array<float, 256> right_cost_part;
        const int nb = std::clamp(config_.bins, 2, 256);
        for (int axis = 0; axis < 3; ++axis) {
            if (!(centroid_box.hi[axis] > centroid_box.lo[axis])) continue;
            const float lo = centroid_box.lo[axis];
            const float scale = bin_scale(centroid_box, axis);
            if (!std::isfinite(scale)) continue;  // extent too small to bin
            std::fill(bins.begin(), bins.begin() + nb, Bin{});
            for (std::uint32_t i = 0; i < n; ++i) {
                Bin& b = bins[bin_of(centers_[idx[i]][axis], lo, scale)];
                b.box.extend(boxes_[idx[i]]);
                ++b.count;
            }
            // Sweep from the right, then from the left, evaluating each plane.
            Box3f acc;
            std::uint32_t count = 0;
            for (int b = nb - 1; b > 0; --b) {
                acc.extend(bins[b].box);
                count += bins[b].count;
                right_cost_part[b] = acc.half_area() * float(count);
            }
            acc = Box3f{};
            count = 0;
            for (int b = 1; b < nb; ++b) {
                acc.extend(bins[b - 1].box);
                count += bins[b - 1].count;
                if (count == 0 || count == n) continue;
                const float cost = config_.traversal_cost +
                                   config_.intersection_cost * (acc.half_area() * float(count) + right_cost_part[b]) *
                                       inv_area;
                if (cost < best.cost) best = {axis, b, cost};
            }
        }
        return best;
    }
};

}  // namespace

Bvh2 build_binned_sah(std::span<const Box3f> boxes, std::span<const Vec3f> centers, const BinnedSahConfig& config) {
    Bvh2 bvh;
    if (boxes.empty()) return bvh;
    Builder(boxes, centers, config, bvh).build();
    bvh.nodes.shrink_to_fit();
    return bvh;
}

double sah_cost(const Bvh2& bvh, float traversal_cost, float intersection_cost) {
    if (bvh.nodes.empty()) return 0;
    const double root_area = std::max(double(bvh.nodes[0].box.half_area()), 1e-30);
    double cost = 0;
    for (const Bvh2Node& n : bvh.nodes) {
        const double rel = double(n.box.half_area()) / root_area;
        cost += n.is_leaf() ? intersection_cost * double(n.count) * rel : traversal_cost * rel;
    }
    return cost;
}

}  // namespace raypack
