#include "accel/motion/motion_bvh.h"

#include <algorithm>
#include <array>
#include <bit>
#include <cassert>
#include <cmath>
#include <stdexcept>

#include "accel/accel.h"
#include "accel/packet_intersector.h"
#include "accel/primitive_intersector.h"
#include "accel/prims/leaf_common.h"
#include "kernels/aabb.h"
#include "kernels/simd.h"

namespace raypack {

namespace {

/// Binned SAH (Wald 2007) over the placements' boxes at mid-shutter
/// centroids; the cost of a subtree's box is the mean of its half areas at
/// the shutter's two ends (Embree's builder for linear bounds does the same).
constexpr int kBins = 16;
constexpr std::uint32_t kMaxLeaf = 4;
/// Entering a placement (a matrix inverse, a transformed ray and a traversal
/// of its object) costs several node tests.
constexpr float kPlacementCost = 4.0f;
/// Past this depth, splits are at the median (so that the depth stays
/// bounded whatever the boxes); the walk's stack holds kStack nodes.
constexpr int kMedianDepth = 48;
constexpr int kStack = 256;
/// Packet width of the batch queries: the widest the build compiles.
#if defined(__AVX512BW__)
constexpr int kPacket = 16;
#elif defined(__AVX2__)
constexpr int kPacket = 8;
#elif defined(__SSE4_2__)
constexpr int kPacket = 4;
#else
constexpr int kPacket = 1;
#endif

float motion_cost(const Box3f& start, const Box3f& end) { return 0.5f * (start.half_area() + end.half_area()); }

}  // namespace

void pad_for_lerp(Box3f& a, Box3f& b) {
    for (int k = 0; k < 3; ++k) {
        // Each of the two products and the sum round once: 4e-7 of the
        // magnitudes is over three ULPs of either.
        const float lo = (std::fabs(a.lo[k]) + std::fabs(b.lo[k])) * 4e-7f;
        const float hi = (std::fabs(a.hi[k]) + std::fabs(b.hi[k])) * 4e-7f;
        a.lo[k] -= lo, b.lo[k] -= lo;
        a.hi[k] += hi, b.hi[k] += hi;
    }
}

MotionBvh::MotionBvh(const Scene& scene, const ObjectAccels& objects, const KernelChoice& kernels, bool brute)
    : scene_(scene), objects_(objects), kernels_(kernels), brute_(brute) {
    std::vector<std::uint32_t> placed(scene.objects.size(), 0);
    for (const Instance& inst : scene.instances) ++placed[inst.object];
    for (const Instance& inst : scene.moving_instances) ++placed[inst.object];
    for (std::uint32_t k = 0; k < scene.moving_instances.size(); ++k) {
        const Instance& inst = scene.moving_instances[k];
        const Scene& object = *scene.objects[inst.object];
        if (placed[inst.object] > 1 || object.placements()) {
            items_.push_back({inst.bounds_start, inst.bounds_end, k, kNoPrim});
            continue;
        }
        for (std::uint32_t p = 0; p < object.primitive_count(); ++p) {
            const Box3f box = primitive_bounds(object, p);
            items_.push_back({transform_box(inst.to_world, box), transform_box(inst.to_world_end, box), k, p});
        }
    }
    const auto n = std::uint32_t(items_.size());
    for (Item& item : items_) pad_for_lerp(item.start, item.end);
    order_.resize(n);
    for (std::uint32_t k = 0; k < n; ++k) order_[k] = k;
    if (brute_ || n == 0) return;
    if (n >= (1u << 28)) throw std::length_error("motion BVH: more than 2^28 moving items");
    nodes_.reserve(2 * std::size_t(n));
    nodes_.emplace_back();
    build(0, 0, n, 1);
    collapse(0);
    nodes_ = {};
}

std::uint32_t MotionBvh::collapse(std::uint32_t node) {
    // Open the costliest inner child until there are four (Embree's collapse).
    std::uint32_t kids[kWidth];
    int count = 0;
    if (nodes_[node].count > 0) {
        kids[count++] = node;  // a leaf root: one child
    } else {
        kids[count++] = nodes_[node].first;
        kids[count++] = nodes_[node].first + 1;
        while (count < kWidth) {
            int open = -1;
            float best = -1;
            for (int j = 0; j < count; ++j) {
                const Node& c = nodes_[kids[j]];
                const float cost = motion_cost(c.start, c.end);
                if (c.count == 0 && cost > best) best = cost, open = j;
            }
            if (open < 0) break;
            const std::uint32_t first = nodes_[kids[open]].first;
            kids[open] = first;
            kids[count++] = first + 1;
        }
    }
    const auto index = std::uint32_t(wide_.size());
    wide_.emplace_back();
    for (int j = 0; j < kWidth; ++j) {
        const bool used = j < count;
        const Node& c = nodes_[used ? kids[j] : node];
        for (int k = 0; k < 3; ++k) {
            wide_[index].lo0[k][j] = used ? c.start.lo[k] : 0.0f;
            wide_[index].hi0[k][j] = used ? c.start.hi[k] : 0.0f;
            wide_[index].lo1[k][j] = used ? c.end.lo[k] : 0.0f;
            wide_[index].hi1[k][j] = used ? c.end.hi[k] : 0.0f;
        }
        wide_[index].child[j] = kEmpty;
    }
    for (int j = 0; j < count; ++j) {
        const Node& c = nodes_[kids[j]];
        assert(c.count <= kMaxLeaf);  // a leaf's count has 3 bits
        const std::uint32_t code = c.count > 0 ? kLeaf | c.first << 3 | c.count : collapse(kids[j]);
        wide_[index].child[j] = code;
    }
    return index;
}

RAYPACK_INLINE std::uint32_t MotionBvh::meet_children(const WideNode& n, const Rayf& ray, const Vec3f& inv_dir, float s, float tfar,
                                       float* entry) const {
    std::uint32_t valid = 0;
    for (int j = 0; j < kWidth; ++j) valid |= std::uint32_t(n.child[j] != kEmpty) << j;
#if defined(__SSE4_2__)
    using F = vfloat<kWidth>;
    const F r(1.0f - s), t(s);
    const auto lerp = [&](const float (&a)[3][kWidth], const float (&b)[3][kWidth]) {
        return Vec3<F>{r * F::load_unaligned(a[0]) + t * F::load_unaligned(b[0]),
                       r * F::load_unaligned(a[1]) + t * F::load_unaligned(b[1]),
                       r * F::load_unaligned(a[2]) + t * F::load_unaligned(b[2])};
    };
    const SlabRay<F> slab{splat<F>(ray.org), splat<F>(inv_dir), {}, F(ray.tnear), F(tfar)};
    F in;
    const mask_of<F> hit = intersect_box<SlabMethod::Robust, F>(mask_of<F>(true), slab, lerp(n.lo0, n.lo1),
                                                                lerp(n.hi0, n.hi1), in);
    in.store_unaligned(entry);
    return valid & std::uint32_t(mask_bits(hit));
#else
    std::uint32_t bits = 0;
    for (int j = 0; j < kWidth; ++j) {
        if (!((valid >> j) & 1u)) continue;
        const Box3f a{{n.lo0[0][j], n.lo0[1][j], n.lo0[2][j]}, {n.hi0[0][j], n.hi0[1][j], n.hi0[2][j]}};
        const Box3f b{{n.lo1[0][j], n.lo1[1][j], n.lo1[2][j]}, {n.hi1[0][j], n.hi1[1][j], n.hi1[2][j]}};
        bits |= std::uint32_t(intersect_aabb(ray.org, inv_dir, lerp_box(a, b, s), ray.tnear, tfar, entry[j])) << j;
    }
    return bits;
#endif
}

void MotionBvh::build(std::uint32_t node, std::uint32_t begin, std::uint32_t end, int depth) {
    depth_ = std::max(depth_, depth);
    const auto centroid = [&](std::uint32_t k) { return (items_[k].start.center() + items_[k].end.center()) * 0.5f; };
    Box3f start, endb, centres;
    for (std::uint32_t i = begin; i < end; ++i) {
        const Item& item = items_[order_[i]];
        start.extend(item.start);
        endb.extend(item.end);
        centres.extend(centroid(order_[i]));
    }
    nodes_[node].start = start;
    nodes_[node].end = endb;
    pad_for_lerp(nodes_[node].start, nodes_[node].end);
    const std::uint32_t count = end - begin;
    const auto make_leaf = [&] {
        nodes_[node].first = begin;
        nodes_[node].count = count;
    };
    if (count == 1) return make_leaf();
    const Vec3f ext = centres.extent();
    const int axis = ext.x >= ext.y && ext.x >= ext.z ? 0 : (ext.y >= ext.z ? 1 : 2);
    const auto key = [&](std::uint32_t k) { return centroid(k)[axis]; };
    std::uint32_t mid = begin;
    if (depth < kMedianDepth && ext[axis] > 0) {
        struct Bin {
            Box3f start, end;
            std::uint32_t count = 0;
        };
        std::array<Bin, kBins> bins{};
        const float scale = float(kBins) / ext[axis];
        const auto bin_of = [&](std::uint32_t k) {
            return std::min(kBins - 1, std::max(0, int((key(k) - centres.lo[axis]) * scale)));
        };
        for (std::uint32_t i = begin; i < end; ++i) {
            Bin& b = bins[std::size_t(bin_of(order_[i]))];
            b.start.extend(items_[order_[i]].start);
            b.end.extend(items_[order_[i]].end);
            ++b.count;
        }
        // Costs of the right side of each plane, then the sweep from the left.
        std::array<float, kBins> right_cost{};
        std::array<std::uint32_t, kBins> right_count{};
        Box3f rs, re;
        std::uint32_t rc = 0;
        for (int b = kBins - 1; b > 0; --b) {
            rs.extend(bins[std::size_t(b)].start);
            re.extend(bins[std::size_t(b)].end);
            rc += bins[std::size_t(b)].count;
            right_cost[std::size_t(b)] = motion_cost(rs, re);
            right_count[std::size_t(b)] = rc;
        }
        Box3f ls, le;
        std::uint32_t lc = 0;
        float best = INFINITY;
        int best_bin = -1;
        for (int b = 1; b < kBins; ++b) {
            ls.extend(bins[std::size_t(b - 1)].start);
            le.extend(bins[std::size_t(b - 1)].end);
            lc += bins[std::size_t(b - 1)].count;
            if (lc == 0 || right_count[std::size_t(b)] == 0) continue;
            const float cost =
                motion_cost(ls, le) * float(lc) + right_cost[std::size_t(b)] * float(right_count[std::size_t(b)]);
            if (cost < best) best = cost, best_bin = b;
        }
        if (best_bin >= 0) {
            const float parent = motion_cost(start, endb);
            const float split_cost = parent > 0 ? 1.0f + kPlacementCost * best / parent : INFINITY;
            if (count <= kMaxLeaf && kPlacementCost * float(count) <= split_cost) return make_leaf();
            mid = std::uint32_t(std::partition(order_.begin() + begin, order_.begin() + end,
                                               [&](std::uint32_t k) { return bin_of(k) < best_bin; }) -
                                order_.begin());
        }
    }
    if (mid == begin || mid == end) {
        // No SAH split (every centre in one point, or too deep): the median
        // along the widest axis, which keeps the depth logarithmic.
        if (!(ext[axis] > 0) && count <= kMaxLeaf) return make_leaf();
        mid = begin + count / 2;
        std::nth_element(order_.begin() + begin, order_.begin() + mid, order_.begin() + end,
                         [&](std::uint32_t a, std::uint32_t b) { return key(a) < key(b); });
    }
    const auto left = std::uint32_t(nodes_.size());
    nodes_.emplace_back();
    nodes_.emplace_back();
    nodes_[node].first = left;
    nodes_[node].count = 0;
    build(left, begin, mid, depth + 1);
    build(left + 1, mid, end, depth + 1);
}

template <bool AnyHit>
bool MotionBvh::test_item(std::uint32_t k, const Rayf& ray, const Vec3f& inv_dir, float s, Hitf& hit,
                          bool box_tested) const {
    const Item& item = items_[k];
    const Instance& inst = scene_.moving_instances[item.instance];
    const float tfar = hit.found() ? std::min(ray.tfar, hit.t) : ray.tfar;
    if (!box_tested) {
        float entry;
        if (!intersect_aabb(ray.org, inv_dir, lerp_box(item.start, item.end, s), ray.tnear, tfar, entry))
            return false;
    }
    Rayf r = ray_in_object(inst.to_object_at(s), ray);
    r.tfar = tfar;
    Hitf h;
    if (item.prim != kNoPrim) {
        const PrimitiveIntersector<float> prims{scene_.objects[inst.object].get(), kernels_};
        if (!prims.intersect(item.prim, r, h)) return false;
    } else {
        const Accel& object = *objects_.accels[inst.object];
        if constexpr (AnyHit) return object.occluded1(r);
        h = object.intersect1(r);
        if (!h.found()) return false;
    }
    if constexpr (AnyHit) return true;
    if (hit.found() && !(h.t < hit.t)) return false;
    hit = h;
    hit.prim = inst.first_hit_id + h.prim;
    return true;
}

template <bool AnyHit>
bool MotionBvh::walk(const Rayf& ray, float s, Hitf& hit, std::uint32_t start) const {
    const Vec3f inv_dir = reciprocal(ray.dir);
    bool found = false;
    if (brute_) {
        for (std::uint32_t k = 0; k < items_.size(); ++k) {
            if (!test_item<AnyHit>(k, ray, inv_dir, s, hit, true)) continue;
            if constexpr (AnyHit) return true;
            found = true;
        }
        return found;
    }
    if (wide_.empty()) return false;
    // Boxes are tested when their parent is visited; the stack keeps each
    // child's entry distance, so that one farther than a hit found since is
    // dropped. Children go on nearest last, so visited first.
    struct Entry {
        std::uint32_t child;
        float entry;
    };
    Entry stack[kStack];
    int top = 0;
    stack[top++] = {start, ray.tnear};
    while (top > 0) {
        const Entry e = stack[--top];
        const float tfar = hit.found() ? std::min(ray.tfar, hit.t) : ray.tfar;
        if (e.entry > tfar) continue;
        if (e.child & kLeaf) {
            const std::uint32_t first = (e.child & ~kLeaf) >> 3, count = e.child & 7u;
            // A leaf of one item: its box was the leaf's, tested already.
            for (std::uint32_t i = first; i < first + count; ++i) {
                if (!test_item<AnyHit>(order_[i], ray, inv_dir, s, hit, count == 1)) continue;
                if constexpr (AnyHit) return true;
                found = true;
            }
            continue;
        }
        float entry[kWidth];
        std::uint32_t bits = meet_children(wide_[e.child], ray, inv_dir, s, tfar, entry);
        const int base = top;
        for (; bits != 0; bits &= bits - 1) {
            const int j = std::countr_zero(bits);
            // Insertion by decreasing entry: the nearest ends on top.
            int k = top++;
            while (k > base && stack[k - 1].entry < entry[j]) stack[k] = stack[k - 1], --k;
            stack[k] = {wide_[e.child].child[j], entry[j]};
        }
    }
    return found;
}

void MotionBvh::intersect(const Rayf& ray, float s, Hitf& hit) const { walk<false>(ray, s, hit); }

bool MotionBvh::occluded(const Rayf& ray, float s) const {
    Hitf none;
    return walk<true>(ray, s, none);
}

template <class F, bool AnyHit>
void MotionBvh::walk_packet(const Rayf* rays, const float* fractions, int count, Hitf* hits,
                            std::uint8_t* occluded) const {
    constexpr int K = lanes_of<F>;
    constexpr int kFewLanes = K / 4;
    alignas(64) float ox[K], oy[K], oz[K], rx[K], ry[K], rz[K], tn[K], tf[K], sv[K];
    Vec3f inv[K];
    for (int l = 0; l < K; ++l) {
        // Lanes past the count: an empty span, which meets no box.
        const Rayf r = l < count ? rays[l] : Rayf{{0, 0, 0}, {1, 1, 1}, 1.0f, 0.0f};
        inv[l] = reciprocal(r.dir);
        ox[l] = r.org.x, oy[l] = r.org.y, oz[l] = r.org.z;
        rx[l] = inv[l].x, ry[l] = inv[l].y, rz[l] = inv[l].z;
        tn[l] = r.tnear;
        tf[l] = l < count && !AnyHit && hits[l].found() ? std::min(r.tfar, hits[l].t) : r.tfar;
        sv[l] = l < count ? fractions[l] : 0.0f;
    }
    const Vec3<F> org{F::load_aligned(ox), F::load_aligned(oy), F::load_aligned(oz)};
    const Vec3<F> rdir{F::load_aligned(rx), F::load_aligned(ry), F::load_aligned(rz)};
    const F tnear = F::load_aligned(tn), s = F::load_aligned(sv), r = F(1.0f) - s;
    std::uint32_t live = count >= 32 ? ~0u : (1u << count) - 1u;
    struct Entry {
        std::uint32_t child;
        std::uint32_t lanes;
    };
    Entry stack[kStack];
    int top = 0;
    stack[top++] = {0, live};
    alignas(64) float entry[K];
    while (top > 0) {
        const Entry e = stack[--top];
        const std::uint32_t lanes = e.lanes & live;
        if (lanes == 0) continue;
        if (std::popcount(lanes) <= kFewLanes) {
            // Too few lanes left to share a node's work: each goes on alone
            // (the static BVHs' single-ray fallback does the same).
            for (std::uint32_t bits = lanes; bits != 0; bits &= bits - 1) {
                const int l = std::countr_zero(bits);
                if constexpr (AnyHit) {
                    Hitf none;
                    if (walk<true>(rays[l], sv[l], none, e.child)) occluded[l] = 1, live &= ~(1u << l);
                } else if (walk<false>(rays[l], sv[l], hits[l], e.child)) {
                    tf[l] = hits[l].t;
                }
            }
            continue;
        }
        if (e.child & kLeaf) {
            const std::uint32_t first = (e.child & ~kLeaf) >> 3, n = e.child & 7u;
            std::uint32_t rest = 0;  // lanes for the placements traced in their objects' structures
            for (std::uint32_t i = first; i < first + n; ++i) {
                const Item& item = items_[order_[i]];
                if (item.prim == kNoPrim) {
                    rest = lanes;
                    continue;
                }
                // A primitive: every lane at once, each ray taken to object
                // space at its own time.
                std::uint32_t bits = lanes & live;
                if (bits == 0) break;
                if (n > 1) {
                    alignas(64) float on[K];
                    for (int l = 0; l < K; ++l) on[l] = (bits >> l) & 1u ? 1.0f : 0.0f;
                    const SlabRay<F> slab{org, rdir, {}, tnear, F::load_aligned(tf)};
                    const Vec3<F> lo{r * F(item.start.lo.x) + s * F(item.end.lo.x), r * F(item.start.lo.y) + s * F(item.end.lo.y),
                                     r * F(item.start.lo.z) + s * F(item.end.lo.z)};
                    const Vec3<F> hi{r * F(item.start.hi.x) + s * F(item.end.hi.x), r * F(item.start.hi.y) + s * F(item.end.hi.y),
                                     r * F(item.start.hi.z) + s * F(item.end.hi.z)};
                    F in;
                    bits = mask_bits(intersect_box<SlabMethod::Robust, F>(F::load_aligned(on) > F(0.0f), slab, lo, hi, in));
                    if (bits == 0) continue;
                }
                const Instance& inst = scene_.moving_instances[item.instance];
                alignas(64) float px[K], py[K], pz[K], dx[K], dy[K], dz[K], on[K];
                for (int l = 0; l < K; ++l) {
                    on[l] = (bits >> l) & 1u ? 1.0f : 0.0f;
                    const Rayf q = on[l] != 0.0f ? ray_in_object(inst.to_object_at(sv[l]), rays[l]) : Rayf{{0, 0, 0}, {1, 1, 1}};
                    px[l] = q.org.x, py[l] = q.org.y, pz[l] = q.org.z, dx[l] = q.dir.x, dy[l] = q.dir.y, dz[l] = q.dir.z;
                }
                RayLanes<F> q;
                q.org = {F::load_aligned(px), F::load_aligned(py), F::load_aligned(pz)};
                q.dir = {F::load_aligned(dx), F::load_aligned(dy), F::load_aligned(dz)};
                q.rdir = reciprocal(q.dir);
                q.tnear = tnear;
                q.tfar = F::load_aligned(tf);
                HitLanes<F> h;
                h.t = F(INFINITY), h.u = h.v = F(0.0f);
                const PacketPrimitiveIntersector<F> prims{scene_.objects[inst.object].get(), kernels_};
                const mask_of<F> valid = F::load_aligned(on) > F(0.0f);
                std::uint32_t got = mask_bits(prims.intersect(valid, q, h, item.prim));
                if (got == 0) continue;
                if constexpr (AnyHit) {
                    for (std::uint32_t b = got; b != 0; b &= b - 1) occluded[std::countr_zero(b)] = 1;
                    live &= ~got;
                } else {
                    alignas(64) float ht[K], hu[K], hv[K];
                    h.t.store_aligned(ht), h.u.store_aligned(hu), h.v.store_aligned(hv);
                    for (; got != 0; got &= got - 1) {
                        const int l = std::countr_zero(got);
                        // Only a nearer hit replaces one found (as the ray by ray walk).
                        if (hits[l].found() && !(ht[l] < hits[l].t)) continue;
                        hits[l] = Hitf{ht[l], inst.first_hit_id + h.prim[l], hu[l], hv[l]};
                        tf[l] = ht[l];
                    }
                }
            }
            for (std::uint32_t bits = rest & live; bits != 0; bits &= bits - 1) {
                const int l = std::countr_zero(bits);
                for (std::uint32_t i = first; i < first + n; ++i) {
                    if (items_[order_[i]].prim != kNoPrim) continue;
                    if constexpr (AnyHit) {
                        Hitf none;
                        if (!test_item<true>(order_[i], rays[l], inv[l], sv[l], none, n == 1)) continue;
                        occluded[l] = 1;
                        live &= ~(1u << l);
                        break;
                    } else {
                        if (test_item<false>(order_[i], rays[l], inv[l], sv[l], hits[l], n == 1)) tf[l] = hits[l].t;
                    }
                }
            }
            continue;
        }
        alignas(64) float on[K];
        for (int l = 0; l < K; ++l) on[l] = (lanes >> l) & 1u ? 1.0f : 0.0f;
        const mask_of<F> active = F::load_aligned(on) > F(0.0f);
        const SlabRay<F> slab{org, rdir, {}, tnear, F::load_aligned(tf)};
        const WideNode& node = wide_[e.child];
        Entry next[kWidth];
        float order[kWidth];
        int m = 0;
        for (int j = 0; j < kWidth; ++j) {
            if (node.child[j] == kEmpty) continue;
            const Vec3<F> lo{r * F(node.lo0[0][j]) + s * F(node.lo1[0][j]), r * F(node.lo0[1][j]) + s * F(node.lo1[1][j]),
                             r * F(node.lo0[2][j]) + s * F(node.lo1[2][j])};
            const Vec3<F> hi{r * F(node.hi0[0][j]) + s * F(node.hi1[0][j]), r * F(node.hi0[1][j]) + s * F(node.hi1[1][j]),
                             r * F(node.hi0[2][j]) + s * F(node.hi1[2][j])};
            F in;
            const std::uint32_t hit = mask_bits(intersect_box<SlabMethod::Robust, F>(active, slab, lo, hi, in));
            if (hit == 0) continue;
            in.store_aligned(entry);
            // Nearest first, judged by the first lane that meets the box.
            const float key = entry[std::countr_zero(hit)];
            int k = m++;
            while (k > 0 && order[k - 1] < key) next[k] = next[k - 1], order[k] = order[k - 1], --k;
            next[k] = {node.child[j], hit};
            order[k] = key;
        }
        for (int k = 0; k < m; ++k) stack[top++] = next[k];
    }
}

void MotionBvh::intersect(std::span<const Rayf> rays, std::span<const float> fractions, std::span<Hitf> hits) const {
    if constexpr (kPacket > 1) {
        if (!brute_) {
            for (std::size_t b = 0; b < rays.size(); b += kPacket) {
                const int n = int(std::min<std::size_t>(kPacket, rays.size() - b));
                walk_packet<vfloat<kPacket>, false>(rays.data() + b, fractions.data() + b, n, hits.data() + b, nullptr);
            }
            return;
        }
    }
    for (std::size_t i = 0; i < rays.size(); ++i) intersect(rays[i], fractions[i], hits[i]);
}

void MotionBvh::occluded(std::span<const Rayf> rays, std::span<const float> fractions,
                         std::span<std::uint8_t> occluded) const {
    if (brute_ || kPacket == 1) {
        for (std::size_t i = 0; i < rays.size(); ++i)
            if (!occluded[i]) occluded[i] = this->occluded(rays[i], fractions[i]) ? 1 : 0;
        return;
    }
    if constexpr (kPacket > 1) for (std::size_t b = 0; b < rays.size(); b += kPacket) {
        const int n = int(std::min<std::size_t>(kPacket, rays.size() - b));
        // Rays already occluded (by the static part) take no lane.
        Rayf open[kPacket];
        float when[kPacket];
        std::uint8_t out[kPacket];
        std::size_t index[kPacket];
        int m = 0;
        for (int l = 0; l < n; ++l) {
            if (occluded[b + std::size_t(l)]) continue;
            open[m] = rays[b + std::size_t(l)], when[m] = fractions[b + std::size_t(l)], out[m] = 0;
            index[m++] = b + std::size_t(l);
        }
        if (m == 0) continue;
        walk_packet<vfloat<kPacket>, true>(open, when, m, nullptr, out);
        for (int l = 0; l < m; ++l) occluded[index[l]] = out[l];
    }
}

}  // namespace raypack
