#pragma once
// One ray against the N child boxes of a wide node in one SIMD slab test
// (Kay & Kajiya 1986), robust and without per-axis min/max.
#include <bit>
#include <cmath>
#include <cstdint>

#include "accel/bvh/wide_bvh.h"

namespace raypack {

/// How a node's N boxes are tested.
///
/// Ordered: Ize's robust form (lo - org) * rdir ("Robust BVH Ray Traversal",
/// JCGT 2013), with each axis's near and far plane chosen once per ray from
/// the sign of the reciprocal direction (Williams et al., "An Efficient and
/// Robust Ray-Box Intersection Algorithm", JGT 2005; Embree's nearX/farX), so
/// there is no per-axis min/max, and with the far distances computed from a
/// reciprocal widened by 1 + 2 gamma(3) and one ulp (for the rounding of
/// that product): Ize's widening folded into the ray, as bvh v2 pads rdir.
/// A direction component that reciprocal() would clamp (a ray parallel to
/// the slab) gets the reciprocal +-inf here: inside the slab the distances
/// are -inf / +inf, outside +inf / -inf (a miss), and on a plane
/// 0 * inf = NaN. x86 min and max return their second operand when one is
/// NaN, and the chain ends with tnear / tfar (never NaN) second, so a NaN
/// never reaches the result: it is dropped, at worst with the other distance
/// of its pair, which only widens [entry, exit]. So, as in Robust, a ray
/// parallel to a slab and inside [lo, hi], boundaries included, is never
/// culled by it. The empty box (lo = +inf, hi = -inf) gives near = +inf or
/// far = -inf: unused child slots need no mask.
/// (A fused form, one FMA per plane with org * rdir rounded outwards per
/// ray, was measured 3-7% slower on Zen 4: the FMAs all compete for the two
/// multiply pipes, while the subtractions go to the adders.)
///
/// Plain, Robust: kernels/aabb.h intersect_box on all six planes, for
/// comparison (unused slots then need a mask, lo_x <= hi_x). Plain loses
/// hits on adversarial rays (aimed at vertices, lying in box planes);
/// `--slabs plain` runs Ordered without the widening instead (make_node_ray).
enum class NodeTest { Ordered, Plain, Robust };

/// The ray as the node test sees it, broadcast to N lanes once per ray.
template <int N>
struct NodeRay {
    using F = vfloat<N>;
    Vec3<F> org, rdir, rdir_far;
    Vec3<F> org_rdir;  ///< Plain only
    F tnear;
    /// Byte offsets in WideNode::bounds of the rows with the near planes; a
    /// far row is its near row's offset xor kFarFlip[axis], which keeps three
    /// registers free in the loop.
    std::uint32_t near_x, near_y, near_z;
    static constexpr std::uint32_t kRow = sizeof(float) * N;
    static constexpr std::uint32_t kFarFlip[3] = {0 ^ 3 * kRow, 1 * kRow ^ 4 * kRow, 2 * kRow ^ 5 * kRow};
};

/// Far-plane reciprocal: widened by 1 + 2 gamma(3), then one ulp away from
/// zero (the float's bits + 1, whatever its sign); +-inf stays.
inline constexpr float kFarWiden = 1.0f + 2.0f * rounding_gamma<float>(3);

/// The closest-hit distance the node tests and the stack pops compare with,
/// widened like the far planes: a hit exactly at tfar (tnear == tfar, a
/// shadow ray that ends on a surface) must not lose its box to the rounding
/// of the entry distance (tests/test_extremes.cpp).
template <class F>
RAYPACK_INLINE F node_tfar(const F& tfar) {
    return tfar * F(kFarWiden);
}

/// `slabs` and `rcp` are `--slabs` and `--rcp`, folded into this per-ray
/// setup so that the node loop is the same code for every variant. Plain
/// slabs with the Ordered test: the far reciprocal is not widened (rdir_far
/// = rdir), i.e. Ize's widening dropped and nothing else; the fused form
/// (NodeTest::Plain) was measured slower (see NodeTest), so this is the fast
/// form here, and it loses hits exactly where the widening matters. Measured
/// (Zen 4, gen:balls:4, 512 x 512, K = 1, 8, 16): within 3% of robust, i.e.
/// the robust test costs the wide trees nothing, unlike bvh2 (1.5x).
template <NodeTest Test, int N>
RAYPACK_INLINE NodeRay<N> make_node_ray(const Rayf& ray, SlabMethod slabs = SlabMethod::Robust,
                                        RcpMethod rcp = RcpMethod::Exact) {
    using F = vfloat<N>;
    alignas(16) float rd[4], rf[4];
    std::uint32_t negative;  // bit a: rdir[a] < 0
    if constexpr (Test == NodeTest::Ordered) {
        // Four lanes at once (x, y, z, unused): one division, no branches.
        // A component reciprocal() would clamp becomes +-inf (see NodeTest);
        // 1 / +-0 already is. Approx: the scalar reciprocal(), as load_packet
        // computes it, so that packet lanes get the same bits.
        using V = vfloat<4>;
        const V d = _mm_setr_ps(ray.dir.x, ray.dir.y, ray.dir.z, 1.0f), inf(INFINITY);
        V q;
        if (rcp == RcpMethod::Exact) {
            q = V(1.0f) / d;
        } else {
            const Vec3f a = reciprocal(ray.dir, rcp);
            q = _mm_setr_ps(a.x, a.y, a.z, 1.0f);
        }
        const V r = select(vabs(d) < V(kMinRcpInput), copysign_of(inf, d), q);
        if (slabs == SlabMethod::Robust) {
            const V w = r * V(kFarWiden);
            const V w_up = _mm_castsi128_ps(_mm_add_epi32(_mm_castps_si128(w), _mm_set1_epi32(1)));
            select(vabs(w) == inf, w, w_up).store_aligned(rf);
        } else {
            r.store_aligned(rf);
        }
        r.store_aligned(rd);
        negative = mask_bits(r < V(0.0f));
    } else {
        const Vec3f r = reciprocal(ray.dir, rcp);
        for (int a = 0; a < 3; ++a) {
            rd[a] = r[a];
            rf[a] = r[a] * kFarWiden;
        }
        negative = (r.x < 0 ? 1u : 0u) | (r.y < 0 ? 2u : 0u) | (r.z < 0 ? 4u : 0u);
    }
    NodeRay<N> n;
    n.org = {F(ray.org.x), F(ray.org.y), F(ray.org.z)};
    n.rdir = {F(rd[0]), F(rd[1]), F(rd[2])};
    n.rdir_far = {F(rf[0]), F(rf[1]), F(rf[2])};
    n.org_rdir = {F(ray.org.x * rd[0]), F(ray.org.y * rd[1]), F(ray.org.z * rd[2])};
    n.tnear = F(ray.tnear);
    constexpr std::uint32_t row = NodeRay<N>::kRow;
    n.near_x = negative & 1u ? 3 * row : 0 * row;
    n.near_y = negative & 2u ? 4 * row : 1 * row;
    n.near_z = negative & 4u ? 5 * row : 2 * row;
    return n;
}

/// Bit i set when the ray meets child box i within [tnear, tfar]; `entry`
/// gets the entry distances.
template <NodeTest Test, int N>
RAYPACK_INLINE std::uint32_t node_hits(const WideNode<N>& node, const NodeRay<N>& r, const vfloat<N>& tfar,
                                       vfloat<N>& entry) {
    using F = vfloat<N>;
    if constexpr (Test == NodeTest::Ordered) {
        const char* base = reinterpret_cast<const char*>(node.bounds);
        auto row = [&](std::uint32_t offset) { return F::load_aligned(reinterpret_cast<const float*>(base + offset)); };
        constexpr const std::uint32_t* flip = NodeRay<N>::kFarFlip;
        const F nx = (row(r.near_x) - r.org.x) * r.rdir.x;
        const F ny = (row(r.near_y) - r.org.y) * r.rdir.y;
        const F nz = (row(r.near_z) - r.org.z) * r.rdir.z;
        const F fx = (row(r.near_x ^ flip[0]) - r.org.x) * r.rdir_far.x;
        const F fy = (row(r.near_y ^ flip[1]) - r.org.y) * r.rdir_far.y;
        const F fz = (row(r.near_z ^ flip[2]) - r.org.z) * r.rdir_far.z;
        // Operand order matters: tnear and tfar last, so that a NaN (a
        // parallel ray on a plane) is dropped (see NodeTest).
        entry = vmax(vmax(nx, ny), vmax(nz, r.tnear));
        const F exit = vmin(vmin(fx, fy), vmin(fz, tfar));
        return mask_bits(entry <= exit);
    } else {
        constexpr SlabMethod method = Test == NodeTest::Plain ? SlabMethod::Plain : SlabMethod::Robust;
        const Vec3<F> lo{F::load_aligned(node.bounds[0]), F::load_aligned(node.bounds[1]),
                         F::load_aligned(node.bounds[2])};
        const Vec3<F> hi{F::load_aligned(node.bounds[3]), F::load_aligned(node.bounds[4]),
                         F::load_aligned(node.bounds[5])};
        const SlabRay<F> slab{r.org, r.rdir, r.org_rdir, r.tnear, tfar};
        return mask_bits(intersect_box<method, F>(lo.x <= hi.x, slab, lo, hi, entry));
    }
}

}  // namespace raypack
