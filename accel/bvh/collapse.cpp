#include "accel/bvh/collapse.h"

#include <algorithm>
#include <array>

namespace raypack {
namespace {

/// What the collapse needs to know of each binary node, computed bottom up.
struct SubtreeInfo {
    std::uint32_t begin = 0, end = 0;  ///< its primitives: prim_index[begin, end)
    std::array<std::uint32_t, 3> count{};  ///< primitives per kind
    bool leaf = false;                  ///< becomes a leaf of the wide tree
};

template <int M>
std::uint32_t blocks_for(const std::array<std::uint32_t, 3>& count) {
    std::uint32_t b = 0;
    for (std::uint32_t c : count) b += (c + M - 1) / M;
    return b;
}

template <int N, int M>
class Collapser {
public:
    Collapser(const Bvh2& bvh, const Scene& scene, const CollapseConfig& config, WideBvh<N, M>& out)
        : bvh_(bvh), scene_(scene), config_(config), out_(out), info_(bvh.nodes.size()) {}

    void run() {
        choose_leaves();
        out_.triangle_layout = config_.triangle_layout;
        out_.nodes.reserve(bvh_.nodes.size() / (N - 1) + 1);
        emit_node(0, 1);
    }

private:
    const Bvh2& bvh_;
    const Scene& scene_;
    const CollapseConfig& config_;
    WideBvh<N, M>& out_;
    std::vector<SubtreeInfo> info_;

    // Children follow their parent in the depth-first layout, so a reverse
    // sweep sees them first. SAH with the wide costs decides the leaves.
    void choose_leaves() {
        std::vector<float> cost(bvh_.nodes.size());
        const float per_binary_node = config_.node_cost / float(N - 1);
        for (std::size_t i = bvh_.nodes.size(); i-- > 0;) {
            const Bvh2Node& node = bvh_.nodes[i];
            SubtreeInfo& s = info_[i];
            const float area = node.box.half_area();
            if (node.is_leaf()) {
                s.begin = node.first;
                s.end = node.first + node.count;
                for (std::uint32_t k = s.begin; k < s.end; ++k)
                    ++s.count[std::size_t(scene_.prims[bvh_.prim_index[k]].kind)];
                s.leaf = true;
                cost[i] = config_.block_cost * float(blocks_for<M>(s.count)) * area;
                continue;
            }
            const std::size_t l = i + 1, r = node.first;
            s.begin = info_[l].begin;
            s.end = info_[r].end;
            for (int k = 0; k < 3; ++k) s.count[k] = info_[l].count[k] + info_[r].count[k];
            const float inner = per_binary_node * area + cost[l] + cost[r];
            cost[i] = inner;
            if (s.end - s.begin <= std::uint32_t(config_.max_leaf_prims)) {
                const float leaf = config_.block_cost * float(blocks_for<M>(s.count)) * area;
                if (leaf <= inner) {
                    s.leaf = true;
                    cost[i] = leaf;
                }
            }
        }
    }

    std::uint32_t emit_node(std::uint32_t v, int depth) {
        out_.depth = std::max(out_.depth, depth);
        // Open the child with the largest surface area until there are N.
        std::array<std::uint32_t, N> slots;
        int n = 0;
        if (info_[v].leaf) {
            slots[n++] = v;  // only at the root: a one-leaf tree
        } else {
            slots[n++] = v + 1;
            slots[n++] = bvh_.nodes[v].first;
        }
        while (n < N) {
            int best = -1;
            float best_area = -1;
            for (int i = 0; i < n; ++i) {
                if (info_[slots[i]].leaf) continue;
                const float a = bvh_.nodes[slots[i]].box.half_area();
                if (a > best_area) best = i, best_area = a;
            }
            if (best < 0) break;
            const std::uint32_t u = slots[best];
            slots[best] = u + 1;
            slots[n++] = bvh_.nodes[u].first;
        }
        const auto index = std::uint32_t(out_.nodes.size());
        WideNode<N>& fresh = out_.nodes.emplace_back();
        for (int i = 0; i < N; ++i) {
            fresh.set_box(i, Box3f{});  // lo = +inf, hi = -inf
            fresh.child[i] = wide_child::kEmpty;
        }
        for (int i = 0; i < n; ++i) {
            const std::uint32_t c = slots[i];
            const std::uint32_t code = info_[c].leaf ? emit_leaf(c) : emit_node(c, depth + 1);
            WideNode<N>& node = out_.nodes[index];  // emit_node may have grown the vector
            node.set_box(i, bvh_.nodes[c].box);
            node.child[i] = code;
        }
        return index;
    }

    /// Packs the subtree's primitives, grouped by kind, into blocks.
    std::uint32_t emit_leaf(std::uint32_t v) {
        ++out_.leaves;
        const SubtreeInfo& s = info_[v];
        std::array<std::vector<std::uint32_t>, 3> by_kind;
        for (std::uint32_t k = s.begin; k < s.end; ++k) {
            const std::uint32_t p = bvh_.prim_index[k];
            by_kind[std::size_t(scene_.prims[p].kind)].push_back(p);
        }
        MixedLeaf runs{};
        int kinds = 0, last_kind = 0;
        for (int k = 0; k < 3; ++k) {
            const std::vector<std::uint32_t>& prims = by_kind[k];
            if (prims.empty()) continue;
            ++kinds;
            last_kind = k;
            runs.first[k] = std::uint32_t(block_count(LeafKind(k)));
            for (std::size_t j = 0; j < prims.size(); j += M) {
                const std::span<const std::uint32_t> chunk(prims.data() + j, std::min<std::size_t>(M, prims.size() - j));
                switch (LeafKind(k)) {
                    case LeafKind::Triangle:
                        pack_triangles<M>(out_.triangles.emplace_back(), chunk, scene_, config_.triangle_layout);
                        break;
                    case LeafKind::Sphere: pack_spheres<M>(out_.spheres.emplace_back(), chunk, scene_); break;
                    default: pack_cones<M>(out_.cones.emplace_back(), chunk, scene_); break;
                }
                ++runs.count[k];
            }
        }
        if (kinds == 1 && runs.count[last_kind] <= wide_child::kMaxBlocks)
            return wide_child::make_leaf(LeafKind(last_kind), runs.first[last_kind], runs.count[last_kind]);
        out_.mixed.push_back(runs);
        return wide_child::make_leaf(LeafKind::Mixed, std::uint32_t(out_.mixed.size() - 1), 1);
    }

    std::size_t block_count(LeafKind k) const {
        return k == LeafKind::Triangle ? out_.triangles.size()
               : k == LeafKind::Sphere ? out_.spheres.size()
                                       : out_.cones.size();
    }
};

/// Primitives in the blocks of one leaf.
template <int N, int M>
std::uint32_t leaf_primitives(const WideBvh<N, M>& bvh, std::uint32_t code) {
    auto count_run = [&](LeafKind k, std::uint32_t first, std::uint32_t n) {
        std::uint32_t c = 0;
        for (std::uint32_t b = first; b < first + n; ++b)
            for (int j = 0; j < M; ++j) {
                const std::uint32_t p = k == LeafKind::Triangle ? bvh.triangles[b].prim[j]
                                        : k == LeafKind::Sphere ? bvh.spheres[b].prim[j]
                                                                : bvh.cones[b].prim[j];
                c += p != kNoPrim;
            }
        return c;
    };
    const LeafKind k = wide_child::kind(code);
    if (k != LeafKind::Mixed) return count_run(k, wide_child::first(code), wide_child::blocks(code));
    const MixedLeaf& m = bvh.mixed[wide_child::first(code)];
    std::uint32_t c = 0;
    for (int j = 0; j < 3; ++j) c += count_run(LeafKind(j), m.first[j], m.count[j]);
    return c;
}

}  // namespace

template <int N, int M>
WideBvh<N, M> collapse_bvh(const Bvh2& bvh, const Scene& scene, const CollapseConfig& config) {
    WideBvh<N, M> out;
    if (bvh.nodes.empty()) return out;
    Collapser<N, M>(bvh, scene, config, out).run();
    return out;
}

template <int N, int M>
double sah_cost(const WideBvh<N, M>& bvh, float traversal_cost, float intersection_cost) {
    if (bvh.nodes.empty()) return 0;
    Box3f root;
    for (int i = 0; i < N; ++i)
        if (bvh.nodes[0].child[i] != wide_child::kEmpty) root.extend(bvh.nodes[0].box(i));
    const double root_area = std::max(double(root.half_area()), 1e-30);
    double cost = traversal_cost;  // the root itself
    for (const WideNode<N>& node : bvh.nodes) {
        for (int i = 0; i < N; ++i) {
            const std::uint32_t c = node.child[i];
            if (c == wide_child::kEmpty) continue;
            const double rel = double(node.box(i).half_area()) / root_area;
            cost += wide_child::is_leaf(c) ? intersection_cost * double(leaf_primitives(bvh, c)) * rel
                                           : traversal_cost * rel;
        }
    }
    return cost;
}

template WideBvh<4, 4> collapse_bvh<4, 4>(const Bvh2&, const Scene&, const CollapseConfig&);
template WideBvh<4, 8> collapse_bvh<4, 8>(const Bvh2&, const Scene&, const CollapseConfig&);
template WideBvh<8, 4> collapse_bvh<8, 4>(const Bvh2&, const Scene&, const CollapseConfig&);
template WideBvh<8, 8> collapse_bvh<8, 8>(const Bvh2&, const Scene&, const CollapseConfig&);
template double sah_cost<4, 4>(const WideBvh<4, 4>&, float, float);
template double sah_cost<4, 8>(const WideBvh<4, 8>&, float, float);
template double sah_cost<8, 4>(const WideBvh<8, 4>&, float, float);
template double sah_cost<8, 8>(const WideBvh<8, 8>&, float, float);

}  // namespace raypack
