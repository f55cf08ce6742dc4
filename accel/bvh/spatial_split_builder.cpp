#include "accel/bvh/spatial_split_builder.h"

#include <cmath>
#include <vector>

#include "accel/bvh/build_ref.h"
#include "accel/bvh/bvh2_finalize.h"

namespace raypack {

void split_box(const Box3f& box, int axis, float position, Box3f& left, Box3f& right) {
    left = box, right = box;
    left.hi[axis] = std::min(box.hi[axis], position);
    right.lo[axis] = std::max(box.lo[axis], position);
    if (left.empty()) left = Box3f{};
    if (right.empty()) right = Box3f{};
}

namespace {

using RefList = std::vector<BuildRef>;

/// The best spatial split: plane `axis` = position between bins.
struct SpatialSplit {
    int axis = -1;
    int bin = 0;
    float position = 0;
    float cost = std::numeric_limits<float>::infinity();
};

class SpatialSplitBuilder {
public:
    SpatialSplitBuilder(std::size_t prims, const BvhBuildConfig& config)
        : config_(config), rule_(config), bins_(std::clamp(config.bins, 2, kMaxSahBins)),
          ref_limit_(std::size_t(double(prims) * std::max(1.0f, config.reference_budget))), refs_alive_(prims) {
        nodes_.reserve(2 * prims);
        prim_index_.reserve(ref_limit_ + prims);
    }

    void build(RefList& refs, const RefBounds& bounds, int depth) {
        if (depth == 1) root_area_ = std::max(bounds.box.half_area(), std::numeric_limits<float>::min());
        const std::uint32_t node = std::uint32_t(nodes_.size());
        nodes_.push_back({bounds.box.box(), 0, 0});
        const std::size_t n = refs.size();
        if (n == 1 || depth >= kBvhMaxDepth) return make_leaf(node, refs);

        const float inv_area = 1.0f / std::max(bounds.box.half_area(), std::numeric_limits<float>::min());
        const BinMap map(bounds.centroids2, object_bins_for(n, bins_));
        ObjectBins object_bins(map.bins);
        object_bins.add(refs.data(), n, map);
        const BinnedSplit object = object_bins.best_split(rule_, inv_area);

        // Spatial splits where the object split's children overlap (Stich et al. sec. 4.5).
        SpatialSplit spatial;
        if (refs_alive_ < ref_limit_ && (!object.valid() || overlap_area(object_bins, object) > config_.spatial_alpha * root_area_))
            spatial = find_spatial_split(refs, bounds.box, inv_area);

        const float best = std::min(object.cost, spatial.cost);
        RefList left, right;
        if (rule_.prefers_leaf(std::uint32_t(n), best) || !std::isfinite(best)) {
            if (rule_.may_be_leaf(std::uint32_t(n))) return make_leaf(node, refs);
            split_middle(refs, left, right);
        } else if (spatial.cost < object.cost && apply_spatial(refs, spatial, left, right)) {
            refs_alive_ += left.size() + right.size() - n;
        } else if (object.valid()) {
            for (const BuildRef& r : refs) (map.bin_of(r, object.axis) < object.bin ? left : right).push_back(r);
        } else {
            split_middle(refs, left, right);
        }
        RefList().swap(refs);  // the children own the references now

        const RefBounds left_bounds = bounds_of(left), right_bounds = bounds_of(right);
        build(left, left_bounds, depth + 1);
        nodes_[node].first = std::uint32_t(nodes_.size());
        build(right, right_bounds, depth + 1);
    }

    Bvh2 finish() { return finalize_bvh2(nodes_, std::move(prim_index_)); }

private:
    const BvhBuildConfig& config_;
    SahRule rule_;
    int bins_;
    std::size_t ref_limit_, refs_alive_;
    float root_area_ = 1;
    std::vector<Bvh2Node> nodes_;
    std::vector<std::uint32_t> prim_index_;

    void make_leaf(std::uint32_t node, const RefList& refs) {
        nodes_[node].first = std::uint32_t(prim_index_.size());
        nodes_[node].count = std::uint32_t(refs.size());
        for (const BuildRef& r : refs) prim_index_.push_back(r.prim());
    }

    static RefBounds bounds_of(const RefList& refs) {
        RefBounds b;
        for (const BuildRef& r : refs) b.extend(r);
        return b;
    }

    static void split_middle(const RefList& refs, RefList& left, RefList& right) {
        left.assign(refs.begin(), refs.begin() + refs.size() / 2);
        right.assign(refs.begin() + refs.size() / 2, refs.end());
    }

    float overlap_area(const ObjectBins& bins, const BinnedSplit& split) const {
        SseBox left, right;
        bins.split_boxes(split, left, right);
        SseBox overlap;
        overlap.lo = _mm_max_ps(left.lo, right.lo);
        overlap.hi = _mm_min_ps(left.hi, right.hi);
        return overlap.half_area();
    }

    void split_ref(const BuildRef& r, int axis, float position, BuildRef& left, BuildRef& right) const {
        const Box3f box = r.box();
        Box3f l, rr;
        if (config_.split_reference) config_.split_reference(r.prim(), box, axis, position, l, rr);
        else split_box(box, axis, position, l, rr);
        left = BuildRef::make(l, r.prim());
        right = BuildRef::make(rr, r.prim());
    }

    static float plane(const SseBox& box, int axis, int bin, int bins) {
        const float lo = box.lo_at(axis), hi = box.hi_at(axis);
        return lo + (hi - lo) * (float(bin) / float(bins));
    }
    static int spatial_bin(float x, float lo, float scale, int bins) {
        return std::clamp(int((x - lo) * scale), 0, bins - 1);
    }

    // Chops each reference into the bins it spans, counting where it enters
    // and where it leaves (Stich et al. sec. 4.3). Small nodes use few bins,
    // as for object splits.
    SpatialSplit find_spatial_split(const RefList& refs, const SseBox& node_box, float inv_area) const {
        const int bins = object_bins_for(refs.size(), bins_);
        SpatialSplit best;
        std::array<SseBox, kMaxSahBins> box;
        std::array<std::uint32_t, kMaxSahBins> entry, exit;
        std::array<float, kMaxSahBins> right_weighted;
        for (int a = 0; a < 3; ++a) {
            const float lo = node_box.lo_at(a), extent = node_box.hi_at(a) - lo;
            if (!(extent > 0)) continue;
            const float scale = float(bins) / extent;
            std::fill_n(box.begin(), bins, SseBox{});
            std::fill_n(entry.begin(), bins, 0u);
            std::fill_n(exit.begin(), bins, 0u);
            for (const BuildRef& r : refs) {
                const int first = spatial_bin(SseBox::lane(r.lo, a), lo, scale, bins);
                const int last = std::max(first, spatial_bin(SseBox::lane(r.hi, a), lo, scale, bins));
                ++entry[first];
                ++exit[last];
                BuildRef rest = r;
                for (int b = first; b < last; ++b) {
                    BuildRef part, next;
                    split_ref(rest, a, plane(node_box, a, b + 1, bins), part, next);
                    box[b].extend(part.lo, part.hi);
                    rest = next;
                }
                box[last].extend(rest.lo, rest.hi);
            }
            SseBox acc;
            std::uint32_t n_right = 0;
            for (int b = bins - 1; b > 0; --b) {
                acc.extend(box[b]);
                n_right += exit[b];
                right_weighted[b] = n_right ? acc.half_area() * float(n_right) : 0.0f;
            }
            acc = SseBox{};
            std::uint32_t n_left = 0;
            for (int b = 1; b < bins; ++b) {
                acc.extend(box[b - 1]);
                n_left += entry[b - 1];
                if (n_left == 0 || right_weighted[b] == 0) continue;
                const float cost = rule_.split_cost(acc.half_area() * float(n_left) + right_weighted[b], inv_area);
                if (cost < best.cost) best = {a, b, plane(node_box, a, b, bins), cost};
            }
        }
        return best;
    }

    // Distributes the references, splitting the straddling ones unless
    // keeping one whole on one side is cheaper (reference unsplitting, Stich
    // et al. sec. 4.4), and keeping them whole once the reference budget is
    // spent. False if a side would stay empty.
    bool apply_spatial(const RefList& refs, const SpatialSplit& split, RefList& left, RefList& right) const {
        std::size_t budget = ref_limit_ - refs_alive_;
        const int a = split.axis;
        const float x = split.position;
        // The sides as the split plane defines them, before unsplitting.
        SseBox left_box, right_box;
        std::size_t n_left = 0, n_right = 0;
        for (const BuildRef& r : refs) {
            const float lo = SseBox::lane(r.lo, a), hi = SseBox::lane(r.hi, a);
            if (lo < x) ++n_left, left_box.extend(r.lo, r.hi);
            if (hi > x || !(lo < x)) ++n_right, right_box.extend(r.lo, r.hi);
        }
        // Unsplit costs compare boxes of the clipped sides; the plane bounds them.
        left_box.hi = _mm_min_ps(left_box.hi, axis_limit(a, x, +1));
        right_box.lo = _mm_max_ps(right_box.lo, axis_limit(a, x, -1));
        const float area_l = left_box.half_area(), area_r = right_box.half_area();
        for (const BuildRef& r : refs) {
            const float lo = SseBox::lane(r.lo, a), hi = SseBox::lane(r.hi, a);
            if (!(lo < x)) { right.push_back(r); continue; }
            if (!(hi > x)) { left.push_back(r); continue; }
            SseBox l1 = left_box, r2 = right_box;
            l1.extend(r.lo, r.hi);
            r2.extend(r.lo, r.hi);
            const float c_split = area_l * float(n_left) + area_r * float(n_right);
            const float c_left = l1.half_area() * float(n_left) + area_r * float(n_right - 1);
            const float c_right = area_l * float(n_left - 1) + r2.half_area() * float(n_right);
            const bool can_split = budget > 0;
            if ((c_left < c_split || !can_split) && c_left <= c_right) { left.push_back(r); continue; }
            if (c_right < c_split || !can_split) { right.push_back(r); continue; }
            --budget;
            BuildRef lp, rp;
            split_ref(r, a, x, lp, rp);
            const bool has_l = !lp.box().empty(), has_r = !rp.box().empty();
            if (has_l) left.push_back(lp);
            if (has_r) right.push_back(rp);
            if (!has_l && !has_r) left.push_back(r);  // a clip that lost everything: keep the reference whole
        }
        if (left.empty() || right.empty()) {
            left.clear(), right.clear();
            return false;
        }
        return true;
    }

    static __m128 axis_limit(int axis, float x, int sign) {
        alignas(16) float v[4];
        const float inf = sign > 0 ? std::numeric_limits<float>::infinity() : -std::numeric_limits<float>::infinity();
        v[0] = v[1] = v[2] = v[3] = inf;
        v[axis] = x;
        return _mm_load_ps(v);
    }
};

}  // namespace

Bvh2 build_spatial_split(std::span<const Box3f> boxes, const BvhBuildConfig& config) {
    if (boxes.empty()) return {};
    RefList refs(boxes.size());
    RefBounds bounds;
    for (std::size_t i = 0; i < boxes.size(); ++i) {
        refs[i] = BuildRef::make(boxes[i], std::uint32_t(i));
        bounds.extend(refs[i]);
    }
    SpatialSplitBuilder builder(boxes.size(), config);
    builder.build(refs, bounds, 1);
    return builder.finish();
}

}  // namespace raypack
