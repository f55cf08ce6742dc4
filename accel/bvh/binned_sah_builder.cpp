#include "accel/bvh/binned_sah_builder.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_invoke.h>
#include <tbb/parallel_reduce.h>

#include <vector>

#include "accel/bvh/build_ref.h"

namespace raypack {
namespace {

// Nodes with at least this many references bin in parallel, and subtrees of
// at least this many build as their own tasks. Both only change who does the
// work, never the result: bin merging is min, max and integer sums.
constexpr std::size_t kParallelBinning = 32 * 1024;
constexpr std::size_t kBinningGrain = 8 * 1024;
constexpr std::size_t kParallelSubtree = 2 * 1024;

class BinnedBuilder {
public:
    BinnedBuilder(BuildRef* refs, Bvh2Node* slots, const BvhBuildConfig& config)
        : refs_(refs), slots_(slots), rule_(config), max_bins_(config.bins) {}

    // The subtree over refs [begin, end) owns slots [slot, slot + 2 (end - begin) - 1):
    // its left child starts at slot + 1, its right child after the left's share.
    void build(std::size_t begin, std::size_t end, std::uint32_t slot, int depth, const RefBounds& bounds) const {
        Bvh2Node& node = slots_[slot];
        node.box = bounds.box.box();
        const std::size_t n = end - begin;
        if (n == 1 || depth >= kBvhMaxDepth) return make_leaf(node, begin, end);

        const BinMap map(bounds.centroids2, object_bins_for(n, max_bins_));
        const BinnedSplit split = find_split(begin, end, map, bounds.box);
        RefBounds left, right;
        std::size_t mid;
        if (!split.valid() || rule_.prefers_leaf(std::uint32_t(n), split.cost)) {
            if (rule_.may_be_leaf(std::uint32_t(n))) return make_leaf(node, begin, end);
            // All centres coincide and the node is too large for a leaf: halve it.
            mid = begin + n / 2;
            for (std::size_t i = begin; i < mid; ++i) left.extend(refs_[i]);
            for (std::size_t i = mid; i < end; ++i) right.extend(refs_[i]);
        } else {
            const int axis = split.axis, bin = split.bin;
            mid = begin + partition_refs(
                              refs_ + begin, n, [&](const BuildRef& r) { return map.bin_of(r, axis) < bin; }, left,
                              right);
        }
        const std::uint32_t left_slot = slot + 1;
        const std::uint32_t right_slot = slot + 2 * std::uint32_t(mid - begin);
        node.first = right_slot;
        node.count = 0;
        auto build_left = [&] { build(begin, mid, left_slot, depth + 1, left); };
        auto build_right = [&] { build(mid, end, right_slot, depth + 1, right); };
        if (n >= kParallelSubtree) {
            tbb::parallel_invoke(build_left, build_right);
        } else {
            build_left();
            build_right();
        }
    }

private:
    BuildRef* refs_;
    Bvh2Node* slots_;
    SahRule rule_;
    int max_bins_;

    static void make_leaf(Bvh2Node& node, std::size_t begin, std::size_t end) {
        node.first = std::uint32_t(begin);
        node.count = std::uint32_t(end - begin);
    }

    BinnedSplit find_split(std::size_t begin, std::size_t end, const BinMap& map, const SseBox& box) const {
        const float inv_area = 1.0f / std::max(box.half_area(), std::numeric_limits<float>::min());
        const std::size_t n = end - begin;
        if (n < kParallelBinning) {
            ObjectBins bins(map.bins);
            bins.add(refs_ + begin, n, map);
            return bins.best_split(rule_, inv_area);
        }
        const ObjectBins bins = tbb::parallel_reduce(
            tbb::blocked_range<std::size_t>(begin, end, kBinningGrain), ObjectBins(map.bins),
            [&](const tbb::blocked_range<std::size_t>& r, ObjectBins acc) {
                acc.add(refs_ + r.begin(), r.size(), map);
                return acc;
            },
            [](ObjectBins a, const ObjectBins& b) {
                a.merge(b);
                return a;
            });
        return bins.best_split(rule_, inv_area);
    }
};

}  // namespace

Bvh2 build_binned_sah(std::span<const Box3f> boxes, const BvhBuildConfig& config) {
    const std::size_t n = boxes.size();
    if (n == 0) return {};
    std::vector<BuildRef> refs(n);
    const RefBounds root = tbb::parallel_reduce(
        tbb::blocked_range<std::size_t>(0, n, 16 * 1024), RefBounds{},
        [&](const tbb::blocked_range<std::size_t>& r, RefBounds acc) {
            for (std::size_t i = r.begin(); i < r.end(); ++i) {
                refs[i] = BuildRef::make(boxes[i], std::uint32_t(i));
                acc.extend(refs[i]);
            }
            return acc;
        },
        [](RefBounds a, const RefBounds& b) {
            a.extend(b);
            return a;
        });
    std::unique_ptr<Bvh2Node[]> slots(new Bvh2Node[2 * n - 1]);
    BinnedBuilder(refs.data(), slots.get(), config).build(0, n, 0, 1, root);
    std::vector<std::uint32_t> prim_index(n);
    for (std::size_t i = 0; i < n; ++i) prim_index[i] = refs[i].prim();
    return finalize_bvh2({slots.get(), 2 * n - 1}, std::move(prim_index));
}

}  // namespace raypack
