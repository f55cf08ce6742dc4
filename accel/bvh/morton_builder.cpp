#include "accel/bvh/morton_builder.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <array>
#include <bit>
#include <vector>

#include "accel/bvh/bvh2_finalize.h"

namespace raypack {
namespace {

/// Spreads the low 10 bits of v so that two zero bits follow each.
std::uint32_t spread_bits(std::uint32_t v) {
    v &= 0x3ffu;
    v = (v | (v << 16)) & 0x030000ffu;
    v = (v | (v << 8)) & 0x0300f00fu;
    v = (v | (v << 4)) & 0x030c30c3u;
    v = (v | (v << 2)) & 0x09249249u;
    return v;
}

struct Keyed {
    std::uint32_t code;
    std::uint32_t prim;
};

/// Stable LSD radix sort on the 30-bit codes, three passes of 10 bits.
void radix_sort(std::vector<Keyed>& keys) {
    std::vector<Keyed> tmp(keys.size());
    for (int shift = 0; shift < 30; shift += 10) {
        std::array<std::uint32_t, 1024> count{};
        for (const Keyed& k : keys) ++count[(k.code >> shift) & 1023u];
        std::uint32_t sum = 0;
        for (std::uint32_t& c : count) {
            const std::uint32_t x = c;
            c = sum;
            sum += x;
        }
        for (const Keyed& k : keys) tmp[count[(k.code >> shift) & 1023u]++] = k;
        keys.swap(tmp);
    }
}

class MortonBuilder {
public:
    MortonBuilder(std::span<const Box3f> boxes, const std::vector<Keyed>& keys, int max_leaf, std::vector<Bvh2Node>& nodes)
        : boxes_(boxes), keys_(keys), max_leaf_(std::uint32_t(std::max(max_leaf, 1))), nodes_(nodes) {}

    // Depth first: the left child directly follows its parent.
    Box3f build(std::uint32_t begin, std::uint32_t end, int depth) {
        const std::uint32_t node = std::uint32_t(nodes_.size());
        nodes_.push_back({});
        const std::uint32_t n = end - begin;
        Box3f box;
        if (n <= max_leaf_ || depth >= kBvhMaxDepth) {
            for (std::uint32_t i = begin; i < end; ++i) box.extend(boxes_[keys_[i].prim]);
            nodes_[node] = {box, begin, n};
            return box;
        }
        const std::uint32_t mid = split_point(begin, end);
        box = build(begin, mid, depth + 1);
        const std::uint32_t right = std::uint32_t(nodes_.size());
        box.extend(build(mid, end, depth + 1));
        nodes_[node] = {box, right, 0};
        return box;
    }

private:
    std::span<const Box3f> boxes_;
    const std::vector<Keyed>& keys_;
    std::uint32_t max_leaf_;
    std::vector<Bvh2Node>& nodes_;

    // The first key with the highest differing bit set (Karras 2012, sec. 4);
    // equal codes split in the middle.
    std::uint32_t split_point(std::uint32_t begin, std::uint32_t end) const {
        const std::uint32_t first = keys_[begin].code, last = keys_[end - 1].code;
        if (first == last) return begin + (end - begin) / 2;
        const std::uint32_t bit = 1u << (31 - std::countl_zero(first ^ last));
        const auto it = std::partition_point(keys_.begin() + begin, keys_.begin() + end,
                                             [&](const Keyed& k) { return (k.code & bit) == 0; });
        return std::uint32_t(it - keys_.begin());
    }
};

}  // namespace

Bvh2 build_morton(std::span<const Box3f> boxes, const BvhBuildConfig& config) {
    const std::size_t n = boxes.size();
    if (n == 0) return {};
    Box3f centroids;
    for (const Box3f& b : boxes) centroids.extend(b.center());
    const Vec3f extent = centroids.extent();
    Vec3f scale;
    for (int a = 0; a < 3; ++a) scale[a] = extent[a] > 0 ? 1023.0f / extent[a] : 0.0f;
    std::vector<Keyed> keys(n);
    tbb::parallel_for(std::size_t(0), n, [&](std::size_t i) {
        const Vec3f c = boxes[i].center();
        std::uint32_t q[3];
        for (int a = 0; a < 3; ++a) q[a] = std::uint32_t(std::clamp((c[a] - centroids.lo[a]) * scale[a], 0.0f, 1023.0f));
        keys[i] = {(spread_bits(q[0]) << 2) | (spread_bits(q[1]) << 1) | spread_bits(q[2]), std::uint32_t(i)};
    });
    radix_sort(keys);
    std::vector<Bvh2Node> nodes;
    nodes.reserve(2 * n);
    MortonBuilder(boxes, keys, config.max_leaf_size, nodes).build(0, std::uint32_t(n), 1);
    std::vector<std::uint32_t> prim_index(n);
    for (std::size_t i = 0; i < n; ++i) prim_index[i] = keys[i].prim;
    return finalize_bvh2(nodes, std::move(prim_index));
}

}  // namespace raypack
