#include "accel/bvh/collapse.h"

#include <algorithm>
#include <array>
#include <cstring>
#include <limits>
#include <stdexcept>

#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

namespace raypack {
namespace {

/// What the collapse needs to know of each binary node, computed bottom up.
struct SubtreeInfo {
    std::uint32_t begin = 0, end = 0;  ///< its primitives: prim_index[begin, end)
    std::array<std::uint32_t, kPrimKinds> count{};  ///< primitives per kind
    bool leaf = false;                  ///< becomes a leaf of the wide tree
};

template <int M>
std::uint32_t blocks_for(const std::array<std::uint32_t, kPrimKinds>& count) {
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
        emit_tree();
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
            for (int k = 0; k < kPrimKinds; ++k) s.count[k] = l.count[k] + r.count[k];
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

    /// Where the next node, blocks and mixed run of a subtree go, and what
    /// its emission saw (deepest level, leaves).
    struct Cursor {
        std::uint32_t node = 0, mixed = 0;
        std::array<std::uint32_t, kPrimKinds> blocks{};  ///< by PrimKind
        int depth = 0;
        std::size_t leaves = 0;
        std::array<std::vector<std::uint32_t>, kPrimKinds> by_kind;  ///< emit_leaf's scratch
    };

    /// What the subtree of the wide node made from binary node v writes:
    /// nodes, blocks per kind and mixed runs (Cursor's counts).
    void count(std::uint32_t v, Cursor& c) const {
        std::array<Slot, N> slots;
        const int n = plan_slots(v, slots);
        ++c.node;
        for (int i = 0; i < n; ++i) {
            if (slots[i].leaf) {
                count_leaf(slots[i].node, c);
            } else {
                count(slots[i].node, c);
            }
        }
    }

    /// What emit_leaf writes for binary subtree v: its blocks, and a mixed
    /// run when it holds several kinds or more blocks than a slot names.
    void count_leaf(std::uint32_t v, Cursor& c) const {
        int kinds = 0;
        std::uint32_t blocks = 0;
        for (int k = 0; k < kPrimKinds; ++k) {
            const std::uint32_t b = (info_[v].count[k] + M - 1) / M;
            c.blocks[k] += b;
            blocks += b;
            kinds += b != 0;
        }
        c.mixed += kinds != 1 || blocks > wide_child::kMaxBlocks;
    }

    /// The wide tree, written in place: the sizes are counted first, so the
    /// arrays are allocated once (grown by doubling they were copied and
    /// faulted in page by page: a third of an 8-million-triangle build), and
    /// with several threads the root's subtrees are written at once, each
    /// from its own offsets. The output is the same for any thread count.
    void emit_tree() {
        std::array<Slot, N> slots;
        const int n = plan_slots(0, slots);
        // Each root slot's share, in the order a depth-first emission writes.
        std::array<Cursor, N> part;
        Cursor total;
        total.node = 1;  // the root
        for (int i = 0; i < n; ++i) {
            Cursor& c = part[i];
            c.node = total.node;
            c.blocks = total.blocks;
            c.mixed = total.mixed;
            Cursor size;
            if (slots[i].leaf) {
                count_leaf(slots[i].node, size);
            } else {
                count(slots[i].node, size);
            }
            total.node += size.node;
            total.mixed += size.mixed;
            for (int k = 0; k < kPrimKinds; ++k) total.blocks[k] += size.blocks[k];
        }
        std::uint64_t all_blocks = 0;
        for (std::uint32_t b : total.blocks) all_blocks += b;
        if (all_blocks > wide_child::kIndexMask ||
            total.mixed > wide_child::kIndexMask)
            throw std::length_error("wide BVH: more leaf blocks than a child slot can address");
        out_.nodes.resize(total.node);
        PrimKinds::until([&]<class Kind>() {
            out_.template blocks<Kind>().resize(total.blocks[std::size_t(Kind::kind)]);
            return false;
        });
        out_.mixed.resize(total.mixed);

        WideNode<N>& root = out_.nodes[0];
        clear_node(root);
        auto emit_slot = [&](int i) {
            Cursor& c = part[i];
            root.set_box(i, bvh_.nodes[slots[i].node].box);
            root.child[i] = slots[i].leaf ? emit_leaf(slots[i].node, c) : emit_node(slots[i].node, 2, c);
        };
        if (total.node >= kParallelEmitNodes && tbb::this_task_arena::max_concurrency() > 1) {
            tbb::parallel_for(0, n, emit_slot);
        } else {
            for (int i = 0; i < n; ++i) emit_slot(i);
        }
        out_.depth = 1;
        for (int i = 0; i < n; ++i) {
            out_.depth = std::max(out_.depth, part[i].depth);
            out_.leaves += part[i].leaves;
        }
    }

    /// A wide tree this large (in nodes) is written by several threads.
    static constexpr std::uint32_t kParallelEmitNodes = 1024;

    static void clear_node(WideNode<N>& node) {
        std::memset(static_cast<void*>(&node), 0, sizeof(node));  // the padding too: the same bytes every build
        for (int i = 0; i < N; ++i) {
            node.set_box(i, Box3f{});  // lo = +inf, hi = -inf
            node.child[i] = wide_child::kEmpty;
        }
    }

    std::uint32_t emit_node(std::uint32_t v, int depth, Cursor& c) {
        c.depth = std::max(c.depth, depth);
        std::array<Slot, N> slots;
        const int n = plan_slots(v, slots);
        const std::uint32_t index = c.node++;
        WideNode<N>& node = out_.nodes[index];
        clear_node(node);
        for (int i = 0; i < n; ++i) {
            const Slot s = slots[i];
            node.set_box(i, bvh_.nodes[s.node].box);
            node.child[i] = s.leaf ? emit_leaf(s.node, c) : emit_node(s.node, depth + 1, c);
        }
        return index;
    }

    /// Packs the subtree's primitives, grouped by kind, into blocks.
    std::uint32_t emit_leaf(std::uint32_t v, Cursor& c) {
        ++c.leaves;
        const SubtreeInfo& s = info_[v];
        auto& by_kind = c.by_kind;  // reused: no allocation per leaf
        for (auto& list : by_kind) list.clear();
        for (std::uint32_t k = s.begin; k < s.end; ++k) {
            const std::uint32_t p = bvh_.prim_index[k];
            by_kind[std::size_t(scene_.prims[p].kind)].push_back(p);
        }
        MixedLeaf runs{};
        int kinds = 0, last_kind = 0;
        for (int k = 0; k < kPrimKinds; ++k) {
            const std::vector<std::uint32_t>& prims = by_kind[k];
            if (prims.empty()) continue;
            ++kinds;
            last_kind = k;
            runs.first[k] = c.blocks[k];
            for (std::size_t j = 0; j < prims.size(); j += M) {
                const std::span<const std::uint32_t> chunk(prims.data() + j, std::min<std::size_t>(M, prims.size() - j));
                const std::uint32_t b = c.blocks[k]++;
                PrimKinds::dispatch(PrimKind(k), [&]<class Kind>() {
                    Kind::template pack<M>(out_.template blocks<Kind>()[b], chunk, scene_, BlockLayout{config_.triangle_layout, config_.objects});
                });
                ++runs.count[k];
            }
        }
        if (kinds == 1 && runs.count[last_kind] <= wide_child::kMaxBlocks)
            return wide_child::make_leaf(std::uint32_t(last_kind), runs.first[last_kind], runs.count[last_kind]);
        const std::uint32_t m = c.mixed++;
        out_.mixed[m] = runs;
        return wide_child::make_leaf(wide_child::kMixed, m, 1);
    }
};

/// Primitives in the blocks of one leaf.
template <int N, int M>
std::uint32_t leaf_primitives(const WideBvh<N, M>& bvh, std::uint32_t code) {
    std::uint32_t c = 0;
    bvh.template for_each_run<false>(code, [&]<class Kind>(const auto* blocks, std::uint32_t n) {
        for (std::uint32_t b = 0; b < n; ++b)
            for (std::uint32_t p : blocks[b].prim) c += p != kNoPrim;
        return false;
    });
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
