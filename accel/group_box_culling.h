#pragma once
// Which packets of a group may meet a primitive's box, before they test the
// primitive: the leaf step of the k-d tree's and the octree's groups of
// packets from one point (as the BVH's groups cull a leaf's primitives,
// accel/bvh/wide_group_traversal.h). Included by their packet walks only.
#include <cstdint>

#include "kernels/aabb.h"
#include "kernels/simd.h"

namespace raypack {

#if defined(__AVX2__)
/// The packets q of a group of G (one lane of a vfloat<8> each, G / 8
/// vectors) whose rays may meet box `b`, widened by `pad`, no farther than
/// tfar[q] (per packet, the largest of its lanes'): bit q. Each packet's
/// rays leave one point, org[.][q], in one direction octant shared by the
/// group (`up`: bit a where they go towards +a), with reciprocal directions
/// in [r_lo, r_hi] per axis. Rounding is monotone, so the corner products
/// (plane - org) * r bound every ray's own distances to the box's planes:
/// a packet left out has no ray that meets the box.
template <int G>
RAYPACK_INLINE std::uint32_t packets_meeting_box(const float (&org)[3][G], const float (&r_lo)[3][G],
                                                 const float (&r_hi)[3][G], std::uint32_t up, const Box3f& b,
                                                 float pad, const vfloat<8> (&tfar)[G / 8]) {
    using PF = vfloat<8>;
    constexpr float inf = std::numeric_limits<float>::infinity();
    std::uint32_t bits = 0;
    for (int h = 0; h < G / 8; ++h) {
        PF entry(-inf), exit(inf);
        for (int a = 0; a < 3; ++a) {
            const bool rising = (up >> a) & 1u;
            const PF o = PF::load_aligned(org[a] + 8 * h);
            const PF rl = PF::load_aligned(r_lo[a] + 8 * h), rh = PF::load_aligned(r_hi[a] + 8 * h);
            const PF dn = PF(rising ? b.lo[a] - pad : b.hi[a] + pad) - o;
            const PF df = PF(rising ? b.hi[a] + pad : b.lo[a] - pad) - o;
            entry = vmax(entry, vmin(dn * rl, dn * rh));
            exit = vmin(exit, vmax(df * rl, df * rh));
        }
        bits |= mask_bits((entry <= exit) & (entry <= tfar[h])) << (8 * h);
    }
    return bits;
}
#endif

}  // namespace raypack
