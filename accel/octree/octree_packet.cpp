#include "accel/octree/octree_packet.h"

#include <array>
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
/// c: child c; the node's empty children are never tried). The parameters
/// are stored by half, so that a child's are loads indexed by its bits: along
/// axis k the lower half spans [t0, tm] and the upper one [tm, t1], so
/// enter[k][h] / leave[k][h] bound half h (tm is stored twice). Chosen by
/// address instead of by pointer selects, a child cost 10 fewer instructions.
template <int K>
struct PacketFrame {
    vfloat<K> enter[3][2], leave[3][2];
    vmask<K> active;
    std::uint32_t children;
    std::uint32_t left;

    /// The node's parameters from its slabs' t0 and t1 along axis k.
    RAYPACK_INLINE void set_axis(int k, const vfloat<K>& t0, const vfloat<K>& t1) {
        enter[k][0] = t0;
        leave[k][0] = enter[k][1] = vfloat<K>(0.5f) * (t0 + t1);
        leave[k][1] = t1;
    }
};

/// Child c's parameters in a frame's enter and leave arrays, flattened:
/// axis k's half is bit 2 - k of c.
constexpr std::uint8_t kHalfIndex[8][3] = {
    {0, 2, 4}, {0, 2, 5}, {0, 3, 4}, {0, 3, 5}, {1, 2, 4}, {1, 2, 5}, {1, 3, 4}, {1, 3, 5},
};

/// bits' children in mirrored numbering, for each mirroring mask a: entry
/// [a][bits] has bit c set where bits has bit c ^ a.
constexpr auto kMirroredChildren = [] {
    std::array<std::array<std::uint8_t, 256>, 8> table{};
    for (unsigned a = 0; a < 8; ++a)
        for (unsigned bits = 0; bits < 256; ++bits) {
            unsigned m = 0;
            for (unsigned c = 0; c < 8; ++c)
                if ((bits >> (c ^ a)) & 1u) m |= 1u << c;
            table[a][bits] = std::uint8_t(m);
        }
    return table;
}();

/// `bits` over the children in mirrored numbering: bit c is bit c ^ a of
/// `bits` (a: the mirroring mask).
RAYPACK_INLINE std::uint32_t mirrored_children(std::uint32_t bits, unsigned a) { return kMirroredChildren[a][bits]; }

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
    // is the top one (12 vectors each, 768 bytes at K = 16).
    PacketFrame<K> stack[kOctreeMaxDepth + 1];
    int sp = 0;
    PacketFrame<K>* f = &stack[0];
    const Vec3<F> lo = splat<F>(tree.cube.lo), hi = splat<F>(tree.cube.hi);
    for (int k = 0; k < 3; ++k) {
        const F od = ray.org[k] * ray.rdir[k];
        const F tlo = plane_distance<Slabs>(lo[k], ray.org[k], ray.rdir[k], od),
                thi = plane_distance<Slabs>(hi[k], ray.org[k], ray.rdir[k], od);
        const bool mirrored = a & (4u >> k);
        f->set_axis(k, mirrored ? thi : tlo, mirrored ? tlo : thi);
    }
    M active = group & (vmax(max3(f->enter[0][0], f->enter[1][0], f->enter[2][0]), ray.tnear) <=
                        vmin(min3(f->leave[0][1], f->leave[1][1], f->leave[2][1]), ray.tfar));
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
        // The child's parameters: named vectors, not arrays (GCC kept arrays
        // of them in memory, six stores a child), at indices from a table
        // (the bits' shifts and masks were 15 instructions a child).
        const std::uint8_t* half = kHalfIndex[c];
        const F* enter = &f->enter[0][0];
        const F* leave = &f->leave[0][0];
        const F x0 = enter[half[0]], y0 = enter[half[1]], z0 = enter[half[2]];
        const F x1 = leave[half[0]], y1 = leave[half[1]], z1 = leave[half[2]];
        M m = f->active & (vmax(max3(x0, y0, z0), ray.tnear) <= vmin(min3(x1, y1, z1), ray.tfar));
        if constexpr (AnyHit) m = m & !done;
        if (none(m)) continue;
        if (node.is_leaf()) {
            test_leaf(node, m);
            if constexpr (AnyHit)
                if (all(done | !group)) return;
            continue;
        }
        PacketFrame<K>* g = &stack[++sp];
        g->set_axis(0, x0, x1);
        g->set_axis(1, y0, y1);
        g->set_axis(2, z0, z1);
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
