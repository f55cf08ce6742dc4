#include "accel/kdtree/kdtree_packet.h"

#include <algorithm>
#include <bit>
#include <cstring>
#include <limits>

#include "accel/kdtree/kdtree_ray_interval.h"
#include "accel/packet_driver.h"
#include "accel/packet_intersector.h"
#include "accel/packet_mailbox.h"
#include "kernels/ray_packet.h"

namespace raypack {
namespace {

/// Lanes of `tie` hit prim at exactly the t they had before: restore the
/// earlier hit where its primitive number is lower. Rare, hence out of line:
/// a call on the common path makes every live vector register spill.
template <int K>
[[gnu::noinline, gnu::cold]] void keep_lowest_on_ties(const vmask<K>& tie, const HitPacket<K>& before,
                                                      HitPacket<K>& hit, std::uint32_t prim) {
    std::uint32_t bits = mask_bits(tie);
    // t too: +0 == -0, and the earlier hit keeps its own sign of zero.
    alignas(64) float t[K], u[K], v[K], bt[K], bu[K], bv[K];
    store_lanes(t, hit.t), store_lanes(u, hit.u), store_lanes(v, hit.v);
    store_lanes(bt, before.t), store_lanes(bu, before.u), store_lanes(bv, before.v);
    for (; bits; bits &= bits - 1) {
        const int l = std::countr_zero(bits);
        if (before.prim[l] < prim) hit.prim[l] = before.prim[l], t[l] = bt[l], u[l] = bu[l], v[l] = bv[l];
    }
    hit.t = load_lanes<vfloat<K>>(t);
    hit.u = load_lanes<vfloat<K>>(u);
    hit.v = load_lanes<vfloat<K>>(v);
}

template <class F>
RAYPACK_INLINE F select_if(bool c, const F& a, const F& b) {
    return c ? a : b;
}

/// Some lane of `tie_bits` had its hit on another primitive than `prim`
/// (a primitive tested again in a later leaf ties with itself, often).
template <int K>
RAYPACK_INLINE bool ties_another_primitive(std::uint32_t tie_bits, const HitPacket<K>& before, std::uint32_t prim) {
    for (; tie_bits; tie_bits &= tie_bits - 1)
        if (before.prim[std::countr_zero(tie_bits)] != prim) return true;
    return false;
}

/// The lanes of `m` get back their hit from `before`.
template <int K>
void restore_lanes(const vmask<K>& m, const HitPacket<K>& before, HitPacket<K>& hit) {
    hit.t = select(m, before.t, hit.t);
    hit.u = select(m, before.u, hit.u);
    hit.v = select(m, before.v, hit.v);
    for (std::uint32_t bits = mask_bits(m); bits; bits &= bits - 1) {
        const int l = std::countr_zero(bits);
        hit.prim[l] = before.prim[l];
    }
}

// The single-ray traversal of kdtree_accel.cpp lane by lane: the same
// widened planes, so every lane visits at least the leaves its single ray
// would, and the same kernels, so the hits are bit for bit the same. A lane
// is active in a node while tmin <= min(tmax, tfar).
// SameSigns: every lane in the root box has the same direction signs (all
// camera packets but those straddling the image's centre lines), so the
// near child is the same for all lanes (Wald's thesis, 2004, 7.1): each
// inner node costs two compares and no per-lane choice of child intervals.
// The nodes visited and the hits are those of the general walk.
template <int K, bool AnyHit, SlabMethod Slabs, bool SameSigns>
void trace_packet(const KdTree& tree, const PacketPrimitiveIntersector<vfloat<K>>& isect, RayPacket<K>& ray,
                  HitPacket<K>& hit, vmask<K> valid, vmask<K>& occluded, vmask<K> in_box, vfloat<K> tmin,
                  vfloat<K> tmax) {
    using F = vfloat<K>;
    using M = vmask<K>;
    const F inf(std::numeric_limits<float>::infinity());
    // Inactive lanes get an empty interval, which stays empty in every child.
    tmin = select(in_box, tmin, inf);
    tmax = select(in_box, tmax, -inf);
    constexpr bool plain = Slabs == SlabMethod::Plain;
    const F margin(plain ? 0.0f : tree.margin);
    // What a split plane along each axis needs, indexed by the node's axis
    // (Vec3's operator[] compiles to a chain of compares and blends).
    struct AxisLanes {
        F org, rdir, org_rdir, slack;
    };
    AxisLanes axes[3];
    for (int a = 0; a < 3; ++a)
        axes[a] = {ray.org[a], ray.rdir[a], ray.org[a] * ray.rdir[a], margin * vabs(ray.rdir[a])};
    const M positive[3] = {ray.rdir.x >= F(0.0f), ray.rdir.y >= F(0.0f), ray.rdir.z >= F(0.0f)};
    // Bit a: the lanes' below child comes first along axis a (SameSigns).
    const std::uint32_t lanes = mask_bits(in_box);
    const std::uint32_t below_first_axes = std::uint32_t((mask_bits(positive[0]) & lanes) != 0) |
                                           std::uint32_t((mask_bits(positive[1]) & lanes) != 0) << 1 |
                                           std::uint32_t((mask_bits(positive[2]) & lanes) != 0) << 2;
    const bool double_ties = isect.kernels.precision == Precision::Double;
    const KdNode* nodes = tree.nodes.data();
    // The far children still to visit, with their intervals: lanes stored
    // one by one (a struct of vectors made GCC copy them through scalar
    // registers and keep tmax in memory).
    alignas(64) float stack_tmin[kKdMaxDepth + 1][K], stack_tmax[kKdMaxDepth + 1][K];
    std::uint32_t stack_node[kKdMaxDepth + 1];
    const auto push = [&](int sp, const F& lo, const F& hi, std::uint32_t node) RAYPACK_INLINE_LAMBDA {
        lo.store_aligned(stack_tmin[sp]);
        hi.store_aligned(stack_tmax[sp]);
        stack_node[sp] = node;
    };
    int sp = 0;
    std::uint32_t current = 0;
    PacketMailbox mailbox;
    // Enters `node` with the lanes that reach it before their closest hit so
    // far (all there is to a pop); false if there are none.
    const auto resume = [&](const F& lo, const F& hi_before_hits, std::uint32_t node) RAYPACK_INLINE_LAMBDA {
        const F hi = vmin(hi_before_hits, ray.tfar);
        M live = lo <= hi;
        if constexpr (AnyHit) live = live & valid;
        if (none(live)) return false;
        current = node;
        tmin = select(live, lo, inf);
        tmax = select(live, hi, -inf);
        return true;
    };
    for (;;) {
        const KdNode node = nodes[current];
        if (!node.is_leaf()) {
            const int a = node.axis();
            const AxisLanes& axis = axes[a];
            // The split broadcast straight from the node (through a scalar
            // register it added two steps to every node's latency).
            float split_pos;
            std::memcpy(&split_pos, &nodes[current].word, sizeof split_pos);
            const F split(split_pos);
            const F t_split = plane_distance<Slabs>(split, axis.org, axis.rdir, axis.org_rdir);
            const F near_end = vmin(tmax, plain ? t_split : t_split + axis.slack);
            const F far_start = vmax(tmin, plain ? t_split : t_split - axis.slack);
            if constexpr (SameSigns) {
                const bool visit_near = any(tmin <= near_end), visit_far = any(far_start <= tmax);
                const bool below_first = (below_first_axes >> a) & 1u;
                const std::uint32_t below = node.below_child(current), above = node.above_child();
                const std::uint32_t near = below_first ? below : above;
                const std::uint32_t far = below_first ? above : below;
                // Child 0 is empty space: not visited (see KdNode).
                if (visit_near && near) {
                    if (visit_far && far) push(sp++, far_start, tmax, far);
                    current = near, tmax = near_end;
                    continue;
                }
                if (!visit_near && far) {
                    current = far, tmin = far_start;
                    continue;
                }
                // Past empty space the far side is entered as if popped.
                if (visit_far && far && resume(far_start, tmax, far)) continue;
            } else {
                // Per lane, below is the near side where the direction is positive.
                const M pos = positive[a];
                const F below_lo = select(pos, tmin, far_start), below_hi = select(pos, near_end, tmax);
                const F above_lo = select(pos, far_start, tmin), above_hi = select(pos, tmax, near_end);
                const bool any_below = any(below_lo <= below_hi), any_above = any(above_lo <= above_hi);
                const std::uint32_t below = node.below_child(current), above = node.above_child();
                // Front to back for the first active lane; the packet takes
                // the above side when it finds no lane below.
                const std::uint32_t first = std::countr_zero(mask_bits(tmin <= tmax));
                const bool below_first = any_below && (!any_above || ((mask_bits(pos) >> first) & 1u));
                const bool visit_second = any_below && any_above;
                const std::uint32_t first_child = below_first ? below : above;
                const std::uint32_t second_child = below_first ? above : below;
                const F first_lo = select_if(below_first, below_lo, above_lo);
                const F first_hi = select_if(below_first, below_hi, above_hi);
                const F second_lo = select_if(below_first, above_lo, below_lo);
                const F second_hi = select_if(below_first, above_hi, below_hi);
                if (first_child) {
                    if (visit_second && second_child) push(sp++, second_lo, second_hi, second_child);
                    current = first_child, tmin = first_lo, tmax = first_hi;
                    continue;
                }
                if (visit_second && second_child && resume(second_lo, second_hi, second_child)) continue;
            }
        } else {
            const std::uint32_t count = node.prim_count();
            const std::uint32_t* prims = tree.leaf_prims(nodes[current]);
            M active = tmin <= tmax;
            for (std::uint32_t k = 0; k < count; ++k) {
                // A test again only finds its own hit: ties go to the lowest primitive.
                std::uint32_t& settled = mailbox.settled(prims[k]);
                if (!(mask_bits(active) & ~settled)) continue;
                settled |= mask_bits(active);
                if constexpr (AnyHit) {
                    const M m = isect.intersect(active, ray, hit, prims[k]);
                    occluded = occluded | m;
                    active = active & !m;
                    if (none(active)) break;
                } else if (double_ties) {  // see kd_tie_tfar()
                    const HitPacket<K> before = hit;
                    const F tfar = ray.tfar;
                    ray.tfar = select(active & (before.t < inf), kd_tie_tfar(tfar), tfar);
                    const M m = isect.intersect(active, ray, hit, prims[k]);
                    const M farther = m & (hit.t > before.t);
                    if (any(farther)) restore_lanes<K>(farther, before, hit);
                    ray.tfar = select(m & !farther, hit.t, tfar);
                    const M tie = m & !farther & (hit.t == before.t);
                    if (any(tie)) [[unlikely]]
                        keep_lowest_on_ties<K>(tie, before, hit, prims[k]);
                } else {
                    const HitPacket<K> before = hit;
                    const M m = isect.intersect(active, ray, hit, prims[k]);
                    // Equal t: the lowest primitive number wins, as in the single-ray path.
                    const M tie = m & (hit.t == before.t);
                    if (ties_another_primitive<K>(mask_bits(tie), before, prims[k])) [[unlikely]]
                        keep_lowest_on_ties<K>(tie, before, hit, prims[k]);
                }
            }
            if constexpr (AnyHit) {
                valid = valid & !occluded;
                if (none(valid)) return;
            }
        }
        // Pop the next node some lane reaches before its closest hit so far.
        for (;;) {
            if (sp == 0) return;
            --sp;
            if (resume(F::load_aligned(stack_tmin[sp]), F::load_aligned(stack_tmax[sp]), stack_node[sp])) break;
        }
    }
}

}  // namespace

template <int K, bool AnyHit>
void kdtree_trace_packets(const KdTree& tree, const Scene& scene, KernelChoice kernels, std::span<const Rayf> rays,
                          std::span<Hitf> hits) {
    using F = vfloat<K>;
    const PacketPrimitiveIntersector<F> isect{&scene, kernels};
    // The slab form is chosen once for all packets, rdir once per packet.
    with_slab_form(kernels.slabs, [&]<SlabMethod Slabs>(SlabTag<Slabs>) {
        trace_in_packets<K, AnyHit>(rays, hits, kernels.rcp, [&](RayPacket<K>& ray, HitPacket<K>& hit, vmask<K> valid,
                                                    vmask<K>& occluded) {
            if (tree.empty()) return;
            vfloat<K> tmin, tmax;
            const vmask<K> in_box = kd_ray_interval<vfloat<K>, Slabs>(valid, ray.org, ray.rdir, ray.tnear, ray.tfar,
                                                                      tree.bounds, tree.margin, tmin, tmax);
            const std::uint32_t lanes = mask_bits(in_box);
            if (!lanes) return;
            bool same_signs = true;
            for (const auto& d : {ray.rdir.x, ray.rdir.y, ray.rdir.z}) {
                const std::uint32_t positive = mask_bits(d >= vfloat<K>(0.0f)) & lanes;
                same_signs = same_signs && (positive == 0 || positive == lanes);
            }
            if (same_signs)
                trace_packet<K, AnyHit, Slabs, true>(tree, isect, ray, hit, valid, occluded, in_box, tmin, tmax);
            else
                trace_packet<K, AnyHit, Slabs, false>(tree, isect, ray, hit, valid, occluded, in_box, tmin, tmax);
        });
    });
}

#if defined(__SSE4_2__)
template void kdtree_trace_packets<4, false>(const KdTree&, const Scene&, KernelChoice, std::span<const Rayf>,
                                               std::span<Hitf>);
template void kdtree_trace_packets<4, true>(const KdTree&, const Scene&, KernelChoice, std::span<const Rayf>,
                                               std::span<Hitf>);
#endif
#if defined(__AVX2__)
template void kdtree_trace_packets<8, false>(const KdTree&, const Scene&, KernelChoice, std::span<const Rayf>,
                                               std::span<Hitf>);
template void kdtree_trace_packets<8, true>(const KdTree&, const Scene&, KernelChoice, std::span<const Rayf>,
                                               std::span<Hitf>);
#endif
#if defined(__AVX512BW__)
template void kdtree_trace_packets<16, false>(const KdTree&, const Scene&, KernelChoice, std::span<const Rayf>,
                                               std::span<Hitf>);
template void kdtree_trace_packets<16, true>(const KdTree&, const Scene&, KernelChoice, std::span<const Rayf>,
                                               std::span<Hitf>);
#endif

}  // namespace raypack
