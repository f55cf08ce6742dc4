#include "accel/kdtree/kdtree_build.h"

#include <tbb/parallel_invoke.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <vector>

namespace raypack {

float kdtree_margin(const Box3f& bounds) {
    const Vec3f e = bounds.extent();
    const float extent = std::max({e.x, e.y, e.z});
    const float coord = std::max({std::fabs(bounds.lo.x), std::fabs(bounds.lo.y), std::fabs(bounds.lo.z),
                                  std::fabs(bounds.hi.x), std::fabs(bounds.hi.y), std::fabs(bounds.hi.z)});
    return 1e-5f * extent + 8.0f * coord * std::numeric_limits<float>::epsilon() +
           std::numeric_limits<float>::min();
}

namespace {

// Event kinds, in the order the sweep needs at equal positions: primitives
// ending at p lie left of a plane at p, planar ones on it, starting ones right.
enum EventType : std::uint8_t { kEnd = 0, kPlanar = 1, kStart = 2 };

struct Event {
    float pos;
    std::uint32_t prim;
    std::uint8_t axis;
    std::uint8_t type;
};

bool operator<(const Event& a, const Event& b) {
    if (a.axis != b.axis) return a.axis < b.axis;
    if (a.pos != b.pos) return a.pos < b.pos;
    if (a.type != b.type) return a.type < b.type;
    return a.prim < b.prim;
}

enum Side : std::uint8_t { kBoth = 0, kLeftOnly = 1, kRightOnly = 2 };

struct Plane {
    int axis = -1;
    float pos = 0;
    bool planar_left = true;
    float cost = std::numeric_limits<float>::infinity();
};

class Builder {
public:
    Builder(std::size_t n, const KdClipFn& clip, const KdTreeConfig& config, float root_area)
        : clip_(clip), config_(config), side_(n, kBoth), root_area_(root_area) {}

    static void add_events(std::uint32_t prim, const Box3f& b, std::vector<Event>& out) {
        for (int a = 0; a < 3; ++a) {
            if (b.lo[a] == b.hi[a]) {
                out.push_back({b.lo[a], prim, std::uint8_t(a), kPlanar});
            } else {
                out.push_back({b.lo[a], prim, std::uint8_t(a), kStart});
                out.push_back({b.hi[a], prim, std::uint8_t(a), kEnd});
            }
        }
    }

    /// Builds the subtree of `voxel` from its sorted events (consumed);
    /// returns its node index, or 0 for empty space (no node).
    std::uint32_t build(std::vector<Event>&& events, std::size_t n, const Box3f& voxel, int depth, KdTree& tree) {
        // Child indices and leaf counts have 30 bits in a KdNode.
        if (tree.nodes.size() >= (std::size_t(1) << 30) || n >= (std::size_t(1) << 30))
            throw std::length_error("kdtree: more than 2^30 nodes or references in a leaf");
        const std::uint32_t index = std::uint32_t(tree.nodes.size());
        tree.nodes.emplace_back();
        tree.depth = std::max(tree.depth, depth);
        const float area = voxel.half_area();
        const float leaf_cost = config_.intersection_cost * float(n);
        const Plane plane = (depth < max_depth_ && n > 0 && area > 0) ? find_plane(events, n, voxel)
                                                                      : Plane{};
        // Termination by the SAH: a leaf when it costs no more than the best split.
        if (!(plane.cost < leaf_cost)) {
            make_leaf(events, n, tree, index);
            tree.sah_cost += double(area) / root_area_ * double(leaf_cost);
            if (n > 0) return index;
            tree.nodes.pop_back();  // empty space: no node (see KdNode)
            return 0;
        }
        tree.sah_cost += double(area) / root_area_ * double(config_.traversal_cost);

        // Classify primitives against the plane (Wald & Havran, sec. 4.2).
        for (const Event& e : events)
            if (e.axis == 0 && e.type != kEnd) side_[e.prim] = kBoth;
        for (const Event& e : events) {
            if (e.axis != plane.axis) continue;
            if (e.type == kEnd && e.pos <= plane.pos) side_[e.prim] = kLeftOnly;
            else if (e.type == kStart && e.pos >= plane.pos) side_[e.prim] = kRightOnly;
            else if (e.type == kPlanar) {
                if (e.pos < plane.pos || (e.pos == plane.pos && plane.planar_left)) side_[e.prim] = kLeftOnly;
                else side_[e.prim] = kRightOnly;
            }
        }
        Box3f left_voxel = voxel, right_voxel = voxel;
        left_voxel.hi[plane.axis] = plane.pos;
        right_voxel.lo[plane.axis] = plane.pos;

        // Split the sorted list: one-sided primitives keep their events in
        // order; straddling ones are clipped to each child and their (few)
        // new events sorted and merged in.
        std::vector<Event> left_only, right_only, left_new, right_new;
        std::size_t n_left = 0, n_right = 0;
        for (const Event& e : events) {
            const Side s = Side(side_[e.prim]);
            if (s == kLeftOnly) left_only.push_back(e);
            else if (s == kRightOnly) right_only.push_back(e);
            if (e.axis == 0 && e.type != kEnd) {
                if (s == kLeftOnly) ++n_left;
                else if (s == kRightOnly) ++n_right;
                else {
                    Box3f b;
                    if (clip_box(e.prim, left_voxel, b)) add_events(e.prim, b, left_new), ++n_left;
                    if (clip_box(e.prim, right_voxel, b)) add_events(e.prim, b, right_new), ++n_right;
                }
            }
        }
        std::vector<Event>().swap(events);
        std::sort(left_new.begin(), left_new.end());
        std::sort(right_new.begin(), right_new.end());
        std::vector<Event> left(left_only.size() + left_new.size());
        std::merge(left_only.begin(), left_only.end(), left_new.begin(), left_new.end(), left.begin());
        std::vector<Event>().swap(left_only);
        std::vector<Event>().swap(left_new);
        std::vector<Event> right(right_only.size() + right_new.size());
        std::merge(right_only.begin(), right_only.end(), right_new.begin(), right_new.end(), right.begin());
        std::vector<Event>().swap(right_only);
        std::vector<Event>().swap(right_new);

        std::uint32_t below, above;
        if (n > kParallelPrims && depth < kParallelDepth) {
            // The two subtrees at once, each into a tree of its own (the
            // right one with its own copy of the side marks), spliced in the
            // serial order: the same tree for any number of threads.
            KdTree below_part, above_part;
            Builder right_builder(*this);
            tbb::parallel_invoke(
                [&] { build(std::move(left), n_left, left_voxel, depth + 1, below_part); },
                [&] { right_builder.build(std::move(right), n_right, right_voxel, depth + 1, above_part); });
            below = splice(below_part, tree);
            above = splice(above_part, tree);
        } else {
            below = build(std::move(left), n_left, left_voxel, depth + 1, tree);
            above = build(std::move(right), n_right, right_voxel, depth + 1, tree);
        }
        if (!below && !above) {
            // Both sides empty (primitives clipped away from both): an empty
            // leaf, which a child index cannot express, in place of two.
            tree.nodes[index] = KdNode::leaf(0, 0);
            --tree.leaves, --tree.empty_leaves;
            return index;
        }
        // An empty below side leaves the above child right after its parent.
        tree.nodes[index] = KdNode::inner(plane.axis, plane.pos, above);
        return index;
    }

    /// Subtrees of more primitives than this within this many levels of the
    /// root are built in parallel (at most 2^kParallelDepth - 1 copies of the
    /// side marks, one byte per primitive each).
    static constexpr std::size_t kParallelPrims = 4096;
    static constexpr int kParallelDepth = 4;

    /// Appends `part` (a subtree built on its own, root at 0) to `tree`;
    /// returns the index of its root there, 0 if the part is empty space.
    static std::uint32_t splice(const KdTree& part, KdTree& tree) {
        const std::size_t base = tree.nodes.size(), prim_base = tree.prim_index.size();
        if (base + part.nodes.size() >= (std::size_t(1) << 30) ||
            prim_base + part.prim_index.size() >= (std::size_t(1) << 32) - 1)
            throw std::length_error("kdtree: more than 2^30 nodes or 2^32 references");
        for (KdNode node : part.nodes) {
            if (!node.is_leaf()) {
                if (node.above_child() != 0)  // 0: empty space
                    node = KdNode::inner(node.axis(), node.split(), node.above_child() + std::uint32_t(base));
            } else if (node.prim_count() > 1) {
                node = KdNode::leaf(node.prim_count(), node.word + std::uint32_t(prim_base));
            }
            tree.nodes.push_back(node);
        }
        tree.prim_index.insert(tree.prim_index.end(), part.prim_index.begin(), part.prim_index.end());
        tree.depth = std::max(tree.depth, part.depth);
        tree.leaves += part.leaves;
        tree.empty_leaves += part.empty_leaves;
        tree.references += part.references;
        tree.sah_cost += part.sah_cost;
        return part.nodes.empty() ? 0 : std::uint32_t(base);
    }

    int max_depth_ = 0;

private:
    bool clip_box(std::uint32_t prim, const Box3f& voxel, Box3f& out) const {
        return clip_(prim, voxel, out);
    }

    /// The SAH sweep over the sorted events of all three axes (Wald &
    /// Havran, Algorithm 4), pbrt's cost with the empty bonus: planes on the
    /// voxel's boundary are not candidates.
    Plane find_plane(const std::vector<Event>& events, std::size_t n, const Box3f& voxel) const {
        Plane best;
        const Vec3f e = voxel.extent();
        const float inv_area = 1.0f / voxel.half_area();
        std::size_t n_left[3] = {0, 0, 0}, n_right[3] = {n, n, n};
        const float kt = config_.traversal_cost, ki = config_.intersection_cost;
        for (std::size_t i = 0; i < events.size();) {
            const int a = events[i].axis;
            const float p = events[i].pos;
            std::size_t ends = 0, planars = 0, starts = 0;
            while (i < events.size() && events[i].axis == a && events[i].pos == p && events[i].type == kEnd) ++ends, ++i;
            while (i < events.size() && events[i].axis == a && events[i].pos == p && events[i].type == kPlanar) ++planars, ++i;
            while (i < events.size() && events[i].axis == a && events[i].pos == p && events[i].type == kStart) ++starts, ++i;
            n_right[a] -= planars + ends;
            if (p > voxel.lo[a] && p < voxel.hi[a]) {
                const int a1 = (a + 1) % 3, a2 = (a + 2) % 3;
                const float cap = e[a1] * e[a2];
                const float left_len = p - voxel.lo[a], right_len = voxel.hi[a] - p;
                const float pl = (cap + left_len * (e[a1] + e[a2])) * inv_area;
                const float pr = (cap + right_len * (e[a1] + e[a2])) * inv_area;
                auto cost = [&](std::size_t nl, std::size_t nr) {
                    const float bonus = (nl == 0 || nr == 0) ? config_.empty_bonus : 0.0f;
                    return kt + ki * (1.0f - bonus) * (pl * float(nl) + pr * float(nr));
                };
                const float c_left = cost(n_left[a] + planars, n_right[a]);
                const float c_right = cost(n_left[a], n_right[a] + planars);
                const float c = std::min(c_left, c_right);
                if (c < best.cost) best = {a, p, c_left <= c_right, c};
            }
            n_left[a] += starts + planars;
        }
        return best;
    }

    void make_leaf(const std::vector<Event>& events, std::size_t n, KdTree& tree, std::uint32_t index) {
        ++tree.leaves;
        tree.references += n;
        if (n == 0) {
            ++tree.empty_leaves;
            tree.nodes[index] = KdNode::leaf(0, 0);
            return;
        }
        std::vector<std::uint32_t> prims;
        prims.reserve(n);
        for (const Event& e : events)
            if (e.axis == 0 && e.type != kEnd) prims.push_back(e.prim);
        std::sort(prims.begin(), prims.end());
        if (prims.size() == 1) {
            tree.nodes[index] = KdNode::leaf(1, prims[0]);
            return;
        }
        tree.nodes[index] = KdNode::leaf(std::uint32_t(prims.size()), std::uint32_t(tree.prim_index.size()));
        tree.prim_index.insert(tree.prim_index.end(), prims.begin(), prims.end());
    }

    const KdClipFn& clip_;
    KdTreeConfig config_;
    std::vector<std::uint8_t> side_;
    double root_area_;
};

bool valid_box(const Box3f& b) { return !b.empty() && all_finite(b.lo) && all_finite(b.hi); }

}  // namespace

KdTree build_kdtree(std::span<const Box3f> boxes, const KdClipFn& clip, const KdTreeConfig& config) {
    KdTree tree;
    std::size_t n = 0;
    for (const Box3f& b : boxes)
        if (valid_box(b)) tree.bounds.extend(b), ++n;
    if (n == 0) return tree;
    tree.margin = kdtree_margin(tree.bounds);

    const KdClipFn box_clip = [&](std::uint32_t prim, const Box3f& voxel, Box3f& out) {
        out.lo = max(boxes[prim].lo, voxel.lo);
        out.hi = min(boxes[prim].hi, voxel.hi);
        return !out.empty();
    };
    const float root_area = tree.bounds.half_area();
    Builder builder(boxes.size(), clip ? clip : box_clip, config, root_area > 0 ? root_area : 1.0f);
    const int auto_depth = int(std::lround(8.0 + 1.3 * std::floor(std::log2(double(n)))));
    builder.max_depth_ = std::clamp(config.max_depth < 0 ? auto_depth : config.max_depth, 0, kKdMaxDepth);

    // The only full sort: all events of all three axes, once (Wald & Havran, sec. 4.1).
    std::vector<Event> events;
    events.reserve(6 * n);
    for (std::uint32_t i = 0; i < boxes.size(); ++i)
        if (valid_box(boxes[i])) Builder::add_events(i, boxes[i], events);
    std::sort(events.begin(), events.end());
    builder.build(std::move(events), n, tree.bounds, 0, tree);
    return tree;
}

}  // namespace raypack
