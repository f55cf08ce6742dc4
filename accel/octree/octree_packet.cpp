#include "accel/octree/octree_packet.h"

#include <bit>
#include <limits>

#include "accel/cell_kernel_variants.h"
#include "accel/packet_driver.h"
#include "accel/packet_intersector.h"
#include "kernels/aabb.h"
#include "kernels/ray_packet.h"

namespace raypack {
namespace {

template <class F>
RAYPACK_INLINE F max3(const F& a, const F& b, const F& c) { return vmax(vmax(a, b), c); }
template <class F>
RAYPACK_INLINE F min3(const F& a, const F& b, const F& c) { return vmin(vmin(a, b), c); }

/// An inner node of the packet walk: each lane's slab parameters, the lanes
/// that entered it, and the children left to try (mirrored numbering, bit
/// c: child c; the node's empty children are never tried).
template <int K>
struct PacketFrame {
    vfloat<K> t0[3], tm[3], t1[3];
    vmask<K> active;
    std::uint32_t children;
    std::uint32_t left;
};

/// `bits` over the children in mirrored numbering: bit c is bit c ^ a of
/// `bits` (a: the mirroring mask).
RAYPACK_INLINE std::uint32_t mirrored_children(std::uint32_t bits, unsigned a) {
    if (a & 1u) bits = ((bits & 0x55u) << 1) | ((bits >> 1) & 0x55u);
    if (a & 2u) bits = ((bits & 0x33u) << 2) | ((bits >> 2) & 0x33u);
    if (a & 4u) bits = ((bits & 0x0Fu) << 4) | ((bits >> 4) & 0x0Fu);
    return bits;
}

// The lanes of `group` share the mirroring mask `a` (their directions' sign
// bits). After mirroring every lane runs towards + on every axis, so a lane
// only ever moves from a child to one with more bits set (the new_node
// table): ascending child numbers are front to back for every lane at once.
// A child is entered by the lanes whose interval [max t0, min t1] meets
// [tnear, tfar], which is the set of children each lane's own walk of
// Revelles et al. visits; tfar shrinks with each hit, so a lane drops out of
// every node behind its closest hit (early termination per lane).
template <int K, bool AnyHit, SlabMethod Slabs>
void walk(const Octree& tree, const PacketPrimitiveIntersector<vfloat<K>>& isect, RayPacket<K>& ray,
          HitPacket<K>& hit, vmask<K> group, unsigned a, vmask<K>& occluded) {
    using F = vfloat<K>;
    using M = vmask<K>;
    const OctreeNode* nodes = tree.nodes.data();
    const std::uint32_t* refs = tree.refs.data();
    // Frames live in the stack array and are never copied: the current node
    // is the top one (9 vectors each, 576 bytes at K = 16).
    PacketFrame<K> stack[kOctreeMaxDepth + 1];
    int sp = 0;
    PacketFrame<K>* f = &stack[0];
    const Vec3<F> lo = splat<F>(tree.cube.lo), hi = splat<F>(tree.cube.hi);
    for (int k = 0; k < 3; ++k) {
        const F od = ray.org[k] * ray.rdir[k];
        const F tlo = plane_distance<Slabs>(lo[k], ray.org[k], ray.rdir[k], od),
                thi = plane_distance<Slabs>(hi[k], ray.org[k], ray.rdir[k], od);
        const bool mirrored = a & (4u >> k);
        f->t0[k] = mirrored ? thi : tlo;
        f->t1[k] = mirrored ? tlo : thi;
        f->tm[k] = F(0.5f) * (f->t0[k] + f->t1[k]);
    }
    M active = group & (vmax(max3(f->t0[0], f->t0[1], f->t0[2]), ray.tnear) <=
                        vmin(min3(f->t1[0], f->t1[1], f->t1[2]), ray.tfar));
    if (none(active)) return;
    M done = active & !active;  // lanes with an occluder (any hit)
    auto test_leaf = [&](const OctreeNode& leaf, M m) {
        for (std::uint32_t k = leaf.first; k < leaf.first + leaf.count; ++k) {
            const M h = isect.intersect(m, ray, hit, refs[k]);
            if constexpr (AnyHit) {
                occluded = occluded | h;
                done = done | h;
                m = m & !h;
                if (none(m)) return;
            }
        }
    };
    if (nodes[0].is_leaf()) {
        test_leaf(nodes[0], active);
        return;
    }
    f->active = active;
    f->children = nodes[0].first;
    f->left = mirrored_children(nodes[0].occupied(), a);
    for (;;) {
        if (f->left == 0) {
            if (sp == 0) return;
            f = &stack[--sp];
            continue;
        }
        const int c = std::countr_zero(f->left);  // ascending: front to back for every lane
        f->left &= f->left - 1;
        const OctreeNode node = nodes[f->children + (unsigned(c) ^ a)];
        const F* c0[3];
        const F* c1[3];
        for (int k = 0; k < 3; ++k) {
            const bool upper = c & (4 >> k);
            c0[k] = upper ? &f->tm[k] : &f->t0[k];
            c1[k] = upper ? &f->t1[k] : &f->tm[k];
        }
        M m = f->active & (vmax(max3(*c0[0], *c0[1], *c0[2]), ray.tnear) <= vmin(min3(*c1[0], *c1[1], *c1[2]), ray.tfar));
        if constexpr (AnyHit) m = m & !done;
        if (none(m)) continue;
        if (node.is_leaf()) {
            test_leaf(node, m);
            if constexpr (AnyHit)
                if (all(done | !group)) return;
            continue;
        }
        PacketFrame<K>* g = &stack[++sp];
        for (int k = 0; k < 3; ++k) {
            const F t0 = *c0[k], t1 = *c1[k];
            g->t0[k] = t0;
            g->t1[k] = t1;
            g->tm[k] = F(0.5f) * (t0 + t1);
        }
        g->active = m;
        g->children = node.first;
        g->left = mirrored_children(node.occupied(), a);
        f = g;
    }
}

template <int K, bool AnyHit, SlabMethod Slabs>
void trace_packet(const Octree& tree, const PacketPrimitiveIntersector<vfloat<K>>& isect, RayPacket<K>& ray,
                  HitPacket<K>& hit, vmask<K> valid, vmask<K>& occluded) {
    using F = vfloat<K>;
    using M = vmask<K>;
    // reciprocal() keeps the sign bit, -0 included: rdir < 0 iff the sign bit of dir is set.
    const M neg[3] = {ray.rdir.x < F(0.0f), ray.rdir.y < F(0.0f), ray.rdir.z < F(0.0f)};
    // One walk per octant present (usually one: coherent packets share their signs).
    M left = valid;
    while (any(left)) {
        const int l = std::countr_zero(mask_bits(left));
        unsigned a = 0;
        M group = left;
        for (int k = 0; k < 3; ++k) {
            const bool n = lane(neg[k], l);
            a |= n ? 4u >> k : 0u;
            group = group & (n ? neg[k] : !neg[k]);
        }
        walk<K, AnyHit, Slabs>(tree, isect, ray, hit, group, a, occluded);
        left = left & !group;
    }
}

}  // namespace

template <int K, bool AnyHit>
void octree_trace_packets(const Octree& tree, const Scene& scene, KernelChoice kernels, std::span<const Rayf> rays,
                          std::span<Hitf> hits) {
    using F = vfloat<K>;
    if (tree.empty()) {
        for (auto& h : hits) h = Hitf{};
        return;
    }
    const PacketPrimitiveIntersector<F> isect{&scene, kernels};
    // The slab form is chosen once for all packets, rdir once per packet.
    with_slab_form(kernels.slabs, [&]<SlabMethod Slabs>(SlabTag<Slabs>) {
        trace_in_packets<K, AnyHit>(rays, hits, kernels.rcp, [&](RayPacket<K>& ray, HitPacket<K>& hit, vmask<K> valid,
                                                    vmask<K>& occluded) {
            trace_packet<K, AnyHit, Slabs>(tree, isect, ray, hit, valid, occluded);
        });
    });
}

#if defined(__SSE4_2__)
template void octree_trace_packets<4, false>(const Octree&, const Scene&, KernelChoice, std::span<const Rayf>,
                                             std::span<Hitf>);
template void octree_trace_packets<4, true>(const Octree&, const Scene&, KernelChoice, std::span<const Rayf>,
                                            std::span<Hitf>);
#endif
#if defined(__AVX2__)
template void octree_trace_packets<8, false>(const Octree&, const Scene&, KernelChoice, std::span<const Rayf>,
                                             std::span<Hitf>);
template void octree_trace_packets<8, true>(const Octree&, const Scene&, KernelChoice, std::span<const Rayf>,
                                            std::span<Hitf>);
#endif
#if defined(__AVX512BW__)
template void octree_trace_packets<16, false>(const Octree&, const Scene&, KernelChoice, std::span<const Rayf>,
                                              std::span<Hitf>);
template void octree_trace_packets<16, true>(const Octree&, const Scene&, KernelChoice, std::span<const Rayf>,
                                             std::span<Hitf>);
#endif

}  // namespace raypack
