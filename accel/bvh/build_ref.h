#pragma once
// Primitive references as the SAH builders move them around, and the object
// binning they share (Wald 2007, sec. 3; the layout of Embree's PrimRef):
// one 32-byte record per reference, box lo with the primitive number in the
// fourth lane, box hi with that number negated, so that lo + hi is twice the
// centre with an exact zero in the fourth lane.
#include <immintrin.h>

#include <algorithm>
#include <array>
#include <bit>
#include <cstdint>
#include <limits>
#include <vector>

#include "kernels/aabb.h"

namespace raypack {

/// Bins of a binned builder at most (config.bins is clamped to it).
inline constexpr int kMaxSahBins = 64;

struct alignas(32) BuildRef {
    __m128 lo;  // x, y, z, primitive number (bits)
    __m128 hi;  // x, y, z, -primitive number (bits)

    static BuildRef make(const Box3f& b, std::uint32_t prim) {
        const float id = std::bit_cast<float>(prim);
        return {_mm_setr_ps(b.lo.x, b.lo.y, b.lo.z, id), _mm_setr_ps(b.hi.x, b.hi.y, b.hi.z, -id)};
    }
    std::uint32_t prim() const { return std::bit_cast<std::uint32_t>(_mm_cvtss_f32(_mm_shuffle_ps(lo, lo, 3))); }
    __m128 centroid2() const { return _mm_add_ps(lo, hi); }  // twice the centre
    Box3f box() const {
        alignas(16) float l[4], h[4];
        _mm_store_ps(l, lo);
        _mm_store_ps(h, hi);
        return {{l[0], l[1], l[2]}, {h[0], h[1], h[2]}};
    }
};
static_assert(sizeof(BuildRef) == 32);

/// A box as two SSE registers (the fourth lane is ignored).
struct SseBox {
    __m128 lo = _mm_set1_ps(std::numeric_limits<float>::infinity());
    __m128 hi = _mm_set1_ps(-std::numeric_limits<float>::infinity());

    void extend(__m128 l, __m128 h) { lo = _mm_min_ps(lo, l); hi = _mm_max_ps(hi, h); }
    void extend(__m128 p) { extend(p, p); }
    void extend(const SseBox& b) { extend(b.lo, b.hi); }
    float half_area() const {
        alignas(16) float e[4];
        _mm_store_ps(e, _mm_sub_ps(hi, lo));
        if (!(e[0] >= 0 && e[1] >= 0 && e[2] >= 0)) return 0;
        return e[0] * e[1] + e[1] * e[2] + e[2] * e[0];
    }
    float lo_at(int axis) const { return lane(lo, axis); }
    float hi_at(int axis) const { return lane(hi, axis); }
    Box3f box() const { return {{lane(lo, 0), lane(lo, 1), lane(lo, 2)}, {lane(hi, 0), lane(hi, 1), lane(hi, 2)}}; }
    static float lane(__m128 v, int i) {
        alignas(16) float f[4];
        _mm_store_ps(f, v);
        return f[i];
    }
};

/// Bounds of references and of their (doubled) centres, as a partition
/// produces them for each side.
struct RefBounds {
    SseBox box;
    SseBox centroids2;
    void extend(const BuildRef& r) {
        box.extend(r.lo, r.hi);
        centroids2.extend(r.centroid2());
    }
    void extend(const RefBounds& o) {
        box.extend(o.box);
        centroids2.extend(o.centroids2);
    }
};

/// Maps a doubled centre to a bin along each axis of the centroid box.
struct BinMap {
    int bins = 0;
    __m128 origin, scale, last_bin;

    BinMap(const SseBox& centroids2, int bin_count) : bins(bin_count) {
        origin = centroids2.lo;
        const __m128 extent = _mm_sub_ps(centroids2.hi, centroids2.lo);
        // A slightly smaller scale keeps the largest centre inside the last bin;
        // an axis without extent maps everything to bin 0 and offers no split.
        const __m128 s = _mm_div_ps(_mm_set1_ps(float(bin_count) * 0.99999f), extent);
        scale = _mm_and_ps(s, _mm_cmpgt_ps(extent, _mm_set1_ps(0.0f)));
        scale = _mm_and_ps(scale, _mm_cmplt_ps(scale, _mm_set1_ps(std::numeric_limits<float>::infinity())));
        last_bin = _mm_set1_ps(float(bin_count - 1));
    }
    /// Bin numbers along x, y, z in the first three lanes.
    __m128i bin_of(const BuildRef& r) const {
        __m128 f = _mm_mul_ps(_mm_sub_ps(r.centroid2(), origin), scale);
        f = _mm_min_ps(_mm_max_ps(f, _mm_setzero_ps()), last_bin);  // max first: a NaN becomes 0
        return _mm_cvttps_epi32(f);
    }
    int bin_of(const BuildRef& r, int axis) const {
        alignas(16) std::int32_t b[4];
        _mm_store_si128(reinterpret_cast<__m128i*>(b), bin_of(r));
        return b[axis];
    }
};

/// The best split a binning found: references in bins [0, bin) go left.
struct BinnedSplit {
    int axis = -1;
    int bin = 0;
    float cost = std::numeric_limits<float>::infinity();
    bool valid() const { return axis >= 0; }
};

/// Bins a node of n references uses: fewer for small nodes, as Embree does
/// (BinMapping in heuristic_binning.h: min(32, 4 + 0.05 n)).
inline int object_bins_for(std::size_t n, int max_bins) {
    return int(std::min<std::size_t>(std::size_t(std::clamp(max_bins, 2, kMaxSahBins)), 4 + n / 20));
}

/// Half areas of three boxes in the first three lanes (fourth lane zero).
inline __m128 half_areas3(const SseBox& a, const SseBox& b, const SseBox& c) {
    __m128 ea = _mm_sub_ps(a.hi, a.lo), eb = _mm_sub_ps(b.hi, b.lo), ec = _mm_sub_ps(c.hi, c.lo);
    // e * e.yzx = (xy, yz, zx, w w); the transpose sums the first three per box.
    __m128 pa = _mm_mul_ps(ea, _mm_shuffle_ps(ea, ea, _MM_SHUFFLE(3, 0, 2, 1)));
    __m128 pb = _mm_mul_ps(eb, _mm_shuffle_ps(eb, eb, _MM_SHUFFLE(3, 0, 2, 1)));
    __m128 pc = _mm_mul_ps(ec, _mm_shuffle_ps(ec, ec, _MM_SHUFFLE(3, 0, 2, 1)));
    __m128 pd = _mm_setzero_ps();
    _MM_TRANSPOSE4_PS(pa, pb, pc, pd);
    return _mm_add_ps(_mm_add_ps(pa, pb), pc);
}

/// Per-axis bins of reference boxes and counts (Wald 2007). The sweep runs
/// the three axes in the lanes of one register, as Embree's does.
struct ObjectBins {
    int bins = 0;
    // Plain arrays: only the first `bins` entries are initialised (a node
    // with few references uses few bins; clearing all would cost more).
    struct Box {
        __m128 lo, hi;
        void extend(__m128 l, __m128 h) { lo = _mm_min_ps(lo, l); hi = _mm_max_ps(hi, h); }
    };
    Box box[3][kMaxSahBins];                          // [axis][bin]: one shift per address
    alignas(16) std::int32_t count[kMaxSahBins][4];  // [bin][axis]

    explicit ObjectBins(int bin_count) : bins(bin_count) {
        const SseBox empty;
        for (int b = 0; b < bins; ++b) {
            for (int a = 0; a < 3; ++a) box[a][b] = {empty.lo, empty.hi};
            _mm_store_si128(reinterpret_cast<__m128i*>(count[b]), _mm_setzero_si128());
        }
    }

    void add(const BuildRef* refs, std::size_t n, const BinMap& map) {
        // Neighbouring references often fall in the same bins, and each
        // update would wait for the last one's store: alternate them
        // between these bins and a second set, merged at the end (min, max
        // and integer sums: the same bins).
        if (n >= std::size_t(4 * bins)) {
            ObjectBins odd(bins);
            std::size_t i = 0;
            for (; i + 1 < n; i += 2) {
                add_one(refs[i], map);
                odd.add_one(refs[i + 1], map);
            }
            if (i < n) add_one(refs[i], map);
            merge(odd);
            return;
        }
        for (std::size_t i = 0; i < n; ++i) add_one(refs[i], map);
    }

    void add_one(const BuildRef& ref, const BinMap& map) {
        alignas(16) std::int32_t b[4];
        _mm_store_si128(reinterpret_cast<__m128i*>(b), map.bin_of(ref));
        const __m128 lo = ref.lo, hi = ref.hi;
        box[0][b[0]].extend(lo, hi);
        box[1][b[1]].extend(lo, hi);
        box[2][b[2]].extend(lo, hi);
        ++count[b[0]][0];
        ++count[b[1]][1];
        ++count[b[2]][2];
    }

    void merge(const ObjectBins& o) {
        for (int b = 0; b < bins; ++b)
            for (int a = 0; a < 3; ++a) {
                box[a][b].extend(o.box[a][b].lo, o.box[a][b].hi);
                count[b][a] += o.count[b][a];
            }
    }

    /// Sweeps every plane between bins; cost as SahRule::split_cost (traversal
    /// cost plus intersection cost times area-weighted counts over the parent).
    /// Ties go to the lower axis, then the lower bin.
    template <class Rule>
    BinnedSplit best_split(const Rule& rule, float inv_parent_area) const {
        __m128 right_weighted[kMaxSahBins];
        SseBox ax, ay, az;
        __m128i n = _mm_setzero_si128();
        for (int b = bins - 1; b > 0; --b) {
            ax.extend(box[0][b].lo, box[0][b].hi), ay.extend(box[1][b].lo, box[1][b].hi),
                az.extend(box[2][b].lo, box[2][b].hi);
            n = _mm_add_epi32(n, load_count(b));
            right_weighted[b] = weighted(half_areas3(ax, ay, az), n);
        }
        const __m128i total = _mm_add_epi32(n, load_count(0));
        const __m128 traversal = _mm_set1_ps(rule.traversal_cost);
        const __m128 intersection = _mm_set1_ps(rule.intersection_cost);
        const __m128 inv_area = _mm_set1_ps(inv_parent_area);
        __m128 best_cost = _mm_set1_ps(std::numeric_limits<float>::infinity());
        __m128i best_bin = _mm_setzero_si128();
        ax = ay = az = SseBox{};
        n = _mm_setzero_si128();
        for (int b = 1; b < bins; ++b) {
            ax.extend(box[0][b - 1].lo, box[0][b - 1].hi), ay.extend(box[1][b - 1].lo, box[1][b - 1].hi),
                az.extend(box[2][b - 1].lo, box[2][b - 1].hi);
            n = _mm_add_epi32(n, load_count(b - 1));
            const __m128 left_weighted = weighted(half_areas3(ax, ay, az), n);
            // Same operations, in the same order, as SahRule::split_cost.
            __m128 cost = _mm_add_ps(
                traversal, _mm_mul_ps(_mm_mul_ps(intersection, _mm_add_ps(left_weighted, right_weighted[b])), inv_area));
            const __m128 valid = _mm_castsi128_ps(
                _mm_and_si128(_mm_cmpgt_epi32(n, _mm_setzero_si128()), _mm_cmplt_epi32(n, total)));
            cost = _mm_or_ps(_mm_and_ps(valid, cost),
                             _mm_andnot_ps(valid, _mm_set1_ps(std::numeric_limits<float>::infinity())));
            const __m128 better = _mm_cmplt_ps(cost, best_cost);
            best_cost = _mm_or_ps(_mm_and_ps(better, cost), _mm_andnot_ps(better, best_cost));
            const __m128i bi = _mm_castps_si128(better);
            best_bin = _mm_or_si128(_mm_and_si128(bi, _mm_set1_epi32(b)), _mm_andnot_si128(bi, best_bin));
        }
        alignas(16) float cost[4];
        alignas(16) std::int32_t bin[4];
        _mm_store_ps(cost, best_cost);
        _mm_store_si128(reinterpret_cast<__m128i*>(bin), best_bin);
        BinnedSplit best;
        for (int a = 0; a < 3; ++a)
            if (cost[a] < best.cost) best = {a, bin[a], cost[a]};
        return best;
    }

    /// Boxes of the two sides of a split.
    void split_boxes(const BinnedSplit& split, SseBox& left, SseBox& right) const {
        for (int b = 0; b < bins; ++b) (b < split.bin ? left : right).extend(box[split.axis][b].lo, box[split.axis][b].hi);
    }

private:
    __m128i load_count(int b) const { return _mm_load_si128(reinterpret_cast<const __m128i*>(count[b])); }
    // area * count, and 0 where the count is 0 (the area of an empty box is not a number).
    static __m128 weighted(__m128 area, __m128i n) {
        const __m128 w = _mm_mul_ps(area, _mm_cvtepi32_ps(n));
        return _mm_and_ps(w, _mm_castsi128_ps(_mm_cmpgt_epi32(n, _mm_setzero_si128())));
    }
};

/// Hoare's partition of refs[0, n) into the side `is_left` accepts first,
/// collecting the bounds of both sides. Returns the size of the left side.
///
/// Hoare's scans swap the k-th reference from the left that belongs right
/// with the k-th from the right that belongs left, for as long as the two
/// have not crossed: exactly the k-th of those below the final split with the
/// k-th of those above it. Done that way, in passes without a branch per
/// reference (as Edelkamp and Weiss's BlockQuicksort, 2016, does Hoare's
/// swaps), the references end in Hoare's order; his scans mispredicted about
/// every other reference of a node that splits evenly.
template <class IsLeft>
std::size_t partition_refs(BuildRef* refs, std::size_t n, IsLeft&& is_left, RefBounds& left, RefBounds& right) {
    constexpr std::size_t kOnStack = 512;
    std::uint8_t side_on_stack[kOnStack];
    std::uint32_t out_of_place_on_stack[kOnStack + 1];  // each pass writes one past its last entry
    std::vector<std::uint8_t> side_on_heap;
    std::vector<std::uint32_t> out_of_place_on_heap;
    std::uint8_t* side = side_on_stack;
    std::uint32_t* out_of_place = out_of_place_on_stack;
    if (n > kOnStack) {
        side_on_heap.resize(n);
        out_of_place_on_heap.resize(n + 1);
        side = side_on_heap.data();
        out_of_place = out_of_place_on_heap.data();
    }
    std::size_t mid = 0;
    for (std::size_t i = 0; i < n; ++i) {
        side[i] = is_left(refs[i]) ? 1 : 0;
        mid += side[i];
    }
    // Right-side references below mid in increasing order, then left-side
    // ones from mid up in decreasing order: as many of each.
    std::size_t below = 0;
    for (std::size_t i = 0; i < mid; ++i) {
        out_of_place[below] = std::uint32_t(i);
        below += side[i] ^ 1u;
    }
    std::size_t above = below;
    for (std::size_t i = n; i-- > mid;) {
        out_of_place[above] = std::uint32_t(i);
        above += side[i];
    }
    for (std::size_t k = 0; k < below; ++k) std::swap(refs[out_of_place[k]], refs[out_of_place[below + k]]);
    for (std::size_t i = 0; i < mid; ++i) left.extend(refs[i]);
    for (std::size_t i = mid; i < n; ++i) right.extend(refs[i]);
    return mid;
}

}  // namespace raypack
