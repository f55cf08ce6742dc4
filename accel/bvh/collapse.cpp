#include "accel/bvh/collapse.h"

#include <algorithm>
#include <array>
#include <limits>
#include <stdexcept>

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

/// A child slot of a wide node: a binary subtree that becomes either a leaf
/// or a wide node.
struct Slot {
    std::uint32_t node;
    bool leaf;
};

template <int N, int M>
class Collapser {
public:
    Collapser(const Bvh2& bvh, const Scene& scene, const CollapseConfig& config, WideBvh<N, M>& out)
        : bvh_(bvh), scene_(scene), config_(config), out_(out), info_(bvh.nodes.size()) {}

    void run() {
        gather_info();
        if (config_.method == CollapseMethod::Greedy) {
            choose_leaves_greedy();
        } else {
            plan_optimal();
        }
        out_.triangle_layout = config_.triangle_layout;
        reserve_output();
        emit_node(0, 1);
    }

private:
    const Bvh2& bvh_;
    const Scene& scene_;
    const CollapseConfig& config_;
    WideBvh<N, M>& out_;
    std::vector<SubtreeInfo> info_;
    // Optimal plan: cost_[n * N + i - 1] is the least SAH cost of subtree n
    // spread over at most i slots; split_ is how many of them go to the left
    // child (0: no better than i - 1 slots).
    std::vector<float> cost_;
    std::vector<std::uint8_t> split_;
    std::array<std::vector<std::uint32_t>, 3> by_kind_;  ///< emit_leaf's scratch

    std::uint32_t left(std::uint32_t n) const { return n + 1; }
    std::uint32_t right(std::uint32_t n) const { return bvh_.nodes[n].first; }

    // Children follow their parent in the depth-first layout, so a reverse
    // sweep sees them first.
    void gather_info() {
        for (std::size_t i = bvh_.nodes.size(); i-- > 0;) {
            const Bvh2Node& node = bvh_.nodes[i];
            SubtreeInfo& s = info_[i];
            if (node.is_leaf()) {
                s.begin = node.first;
                s.end = node.first + node.count;
                for (std::uint32_t k = s.begin; k < s.end; ++k)
                    ++s.count[std::size_t(scene_.prims[bvh_.prim_index[k]].kind)];
                continue;
            }
            const SubtreeInfo &l = info_[i + 1], &r = info_[node.first];
            s.begin = l.begin;
            s.end = r.end;
            for (int k = 0; k < 3; ++k) s.count[k] = l.count[k] + r.count[k];
        }
    }

    float leaf_cost(std::uint32_t n) const {
        const SubtreeInfo& s = info_[n];
        if (!bvh_.nodes[n].is_leaf() && s.end - s.begin > std::uint32_t(config_.max_leaf_prims))
            return std::numeric_limits<float>::infinity();
        return config_.block_cost * float(blocks_for<M>(s.count)) * bvh_.nodes[n].box.half_area();
    }

    // Greedy: a binary subtree becomes a leaf when its blocks cost less than
    // its nodes and leaves would, counting 1/(N-1) of a wide node per binary
    // inner node (an N-wide node replaces about N-1 binary ones).
    void choose_leaves_greedy() {
        std::vector<float> cost(bvh_.nodes.size());
        const float per_binary_node = config_.node_cost / float(N - 1);
        for (std::size_t i = bvh_.nodes.size(); i-- > 0;) {
            const auto n = std::uint32_t(i);
            const float leaf = leaf_cost(n);
            if (bvh_.nodes[n].is_leaf()) {
                info_[n].leaf = true;
                cost[n] = leaf;
                continue;
            }
            const float inner = per_binary_node * bvh_.nodes[n].box.half_area() + cost[left(n)] + cost[right(n)];
            info_[n].leaf = leaf <= inner;
            cost[n] = std::min(leaf, inner);
        }
    }

    // SAH-optimal collapse (Ylitie, Karras, Laine, "Efficient Incoherent Ray
    // Traversal on GPUs Through Compressed Wide BVHs", HPG 2017, section 4.1):
    // for each binary node n and slot budget i, the cheapest way to hang n's
    // subtree below a wide node using at most i child slots, where one slot
    // holds either a leaf (blocks * block_cost * area) or a wide node
    // (node_cost * area plus its own N slots).
    void plan_optimal() {
        const std::size_t count = bvh_.nodes.size();
        cost_.assign(count * N, 0.0f);
        split_.assign(count * N, 0);
        for (std::size_t i = count; i-- > 0;) {
            const auto n = std::uint32_t(i);
            float* c = &cost_[n * N];
            std::uint8_t* k_best = &split_[n * N];
            const float leaf = leaf_cost(n);
            if (bvh_.nodes[n].is_leaf()) {
                info_[n].leaf = true;
                std::fill(c, c + N, leaf);
                continue;
            }
            const float* cl = &cost_[left(n) * N];
            const float* cr = &cost_[right(n) * N];
            // spread[j]: j slots shared by the two children.
            std::array<float, N + 1> spread;
            std::array<std::uint8_t, N + 1> spread_k{};
            for (int j = 2; j <= N; ++j) {
                spread[j] = std::numeric_limits<float>::infinity();
                for (int k = 1; k < j; ++k) {
                    const float v = cl[k - 1] + cr[j - k - 1];
                    if (v < spread[j]) spread[j] = v, spread_k[j] = std::uint8_t(k);
                }
            }
            const float inner = config_.node_cost * bvh_.nodes[n].box.half_area() + spread[N];
            info_[n].leaf = leaf <= inner;
            c[0] = std::min(leaf, inner);
            k_best[0] = spread_k[N];  // the split of n's own wide node
            for (int j = 2; j <= N; ++j) {
                if (spread[j] < c[j - 2]) {
                    c[j - 1] = spread[j];
                    k_best[j - 1] = spread_k[j];
                } else {
                    c[j - 1] = c[j - 2];
                    k_best[j - 1] = 0;
                }
            }
        }
    }

    /// Room for every node and block at once. Grown by doubling, the arrays
    /// were copied and their fresh pages faulted in again at each step: at 8
    /// million triangles page faults were a third of the build (perf). The
    /// bounds are loose (a leaf of the wide tree holds at most one part-full
    /// block per kind, and there are no more of them than binary leaves), but
    /// pages never written are never faulted in.
    void reserve_output() {
        std::size_t binary_leaves = 0;
        for (const Bvh2Node& node : bvh_.nodes) binary_leaves += node.is_leaf();
        const std::array<std::uint32_t, 3>& total = info_[0].count;
        auto blocks = [&](LeafKind k) {
            const std::uint32_t c = total[std::size_t(k)];
            return std::size_t(c / M) + std::min<std::size_t>(c, binary_leaves);
        };
        out_.nodes.reserve(bvh_.nodes.size() / (N - 1) + 1);
        out_.triangles.reserve(blocks(LeafKind::Triangle));
        out_.spheres.reserve(blocks(LeafKind::Sphere));
        out_.cones.reserve(blocks(LeafKind::Cone));
    }

    /// Subtree m spread over at most i slots, as the optimal plan says.
    void gather(std::uint32_t m, int i, std::array<Slot, N>& slots, int& n) const {
        while (i > 1 && split_[m * N + i - 1] == 0) --i;
        if (i == 1) {
            slots[n++] = {m, info_[m].leaf};
            return;
        }
        const int k = split_[m * N + i - 1];
        gather(left(m), k, slots, n);
        gather(right(m), i - k, slots, n);
    }

    /// The child slots of the wide node made from binary node v.
    int plan_slots(std::uint32_t v, std::array<Slot, N>& slots) const {
        int n = 0;
        if (info_[v].leaf) {
            slots[n++] = {v, true};  // only at the root: a one-leaf tree
            return n;
        }
        if (config_.method == CollapseMethod::Optimal) {
            const int k = split_[v * N];
            gather(left(v), k, slots, n);
            gather(right(v), N - k, slots, n);
            return n;
        }
        // Greedy: open the child with the largest surface area until there are N.
        slots[n++] = {left(v), info_[left(v)].leaf};
        slots[n++] = {right(v), info_[right(v)].leaf};
        while (n < N) {
            int best = -1;
            float best_area = -1;
            for (int i = 0; i < n; ++i) {
                if (slots[i].leaf) continue;
                const float a = bvh_.nodes[slots[i].node].box.half_area();
                if (a > best_area) best = i, best_area = a;
            }
            if (best < 0) break;
            const std::uint32_t u = slots[best].node;
            slots[best] = {left(u), info_[left(u)].leaf};
            slots[n++] = {right(u), info_[right(u)].leaf};
        }
        return n;
    }

    std::uint32_t emit_node(std::uint32_t v, int depth) {
        out_.depth = std::max(out_.depth, depth);
        std::array<Slot, N> slots;
        const int n = plan_slots(v, slots);
        const auto index = std::uint32_t(out_.nodes.size());
        WideNode<N>& fresh = out_.nodes.emplace_back();
        for (int i = 0; i < N; ++i) {
            fresh.set_box(i, Box3f{});  // lo = +inf, hi = -inf
            fresh.child[i] = wide_child::kEmpty;
        }
        for (int i = 0; i < n; ++i) {
            const Slot c = slots[i];
            const std::uint32_t code = c.leaf ? emit_leaf(c.node) : emit_node(c.node, depth + 1);
            WideNode<N>& node = out_.nodes[index];  // emit_node may have grown the vector
            node.set_box(i, bvh_.nodes[c.node].box);
            node.child[i] = code;
        }
        return index;
    }

    /// Packs the subtree's primitives, grouped by kind, into blocks.
    std::uint32_t emit_leaf(std::uint32_t v) {
        ++out_.leaves;
        const SubtreeInfo& s = info_[v];
        auto& by_kind = by_kind_;  // reused: no allocation per leaf
        for (auto& list : by_kind) list.clear();
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
        if (kinds == 1 && runs.count[last_kind] <= wide_child::kMaxBlocks &&
            runs.first[last_kind] <= wide_child::kIndexMask)
            return wide_child::make_leaf(LeafKind(last_kind), runs.first[last_kind], runs.count[last_kind]);
        if (out_.mixed.size() > wide_child::kIndexMask)
            throw std::length_error("wide BVH: more leaf runs than a child slot can address");
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
