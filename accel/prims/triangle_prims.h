#pragma once
// Triangles as a leaf primitive kind: their block, and their test in every
// form a traversal calls (see accel/prims/prim_kinds.h).
#include <cstdint>
#include <span>

#include "accel/kernel_choice.h"
#include "accel/prims/leaf_common.h"
#include "kernels/ray_packet.h"
#include "kernels/triangle.h"
#include "scene/scene.h"

namespace raypack {

template <int M>
struct TriangleBlock {
    float p0[3][M];
    float a[3][M];   ///< Edges: p0 - p1; Vertices: p1
    float b[3][M];   ///< Edges: p2 - p0; Vertices: p2
    float ng[3][M];  ///< Edges: (p0 - p1) x (p2 - p0); Vertices: unused
    std::uint32_t prim[M];
};  // total: 52 M bytes (208 for M = 4, 416 for M = 8)
static_assert(sizeof(TriangleBlock<4>) == 208 && sizeof(TriangleBlock<8>) == 416);

struct TrianglePrims {
    static constexpr PrimKind kind = PrimKind::Triangle;
    template <int M>
    using Block = TriangleBlock<M>;

    /// Fills `block` from up to M triangles (scene primitive numbers).
    template <int M>
    static void pack(Block<M>& block, std::span<const std::uint32_t> prims, const Scene& scene,
                     const BlockLayout& layout);

    /// One ray against the M triangles of a block (1 x M).
    template <TriangleMethod TM, class F, int M>
    static RAYPACK_INLINE mask_of<F> intersect_block(const Block<M>& b, SphereMethod, const LeafRay<F>& r,
                                                     const F& tfar, F& t, F& u, F& v) {
        static_assert(lanes_of<F> == M);
        const mask_of<F> all(true);
        const Vec3<F> p0 = load_vec<F>(b.p0), a = load_vec<F>(b.a), c = load_vec<F>(b.b);
        if constexpr (TM == TriangleMethod::Moeller) {
            return intersect_triangle_moeller_edges<F>(all, r.org, r.dir, r.tnear, tfar, p0, a, c, load_vec<F>(b.ng),
                                                       t, u, v);
        } else if constexpr (TM == TriangleMethod::Watertight) {
            return intersect_triangle_watertight<F>(all, r.watertight, r.tnear, tfar, p0, a, c, t, u, v);
        } else {
            return intersect_triangle_plane<F>(all, r.org, r.dir, r.tnear, tfar, p0, a, c, t, u, v);
        }
    }

    /// The active lanes of a packet against triangle j of a block (K x 1).
    /// Not const locals: see accel/bvh/wide_packet_traversal.h.
    template <TriangleMethod TM, class F, int M>
    static RAYPACK_INLINE mask_of<F> intersect_slot(const Block<M>& b, int j, SphereMethod, const LeafRay<F>& r,
                                                    const mask_of<F>& active, const F& tfar, F& t, F& u, F& v) {
        Vec3<F> p0 = broadcast_row<F>(b.p0, j), a = broadcast_row<F>(b.a, j), c = broadcast_row<F>(b.b, j);
        if constexpr (TM == TriangleMethod::Moeller) {
            Vec3<F> ng = broadcast_row<F>(b.ng, j);
            return intersect_triangle_moeller_edges<F>(active, r.org, r.dir, r.tnear, tfar, p0, a, c, ng, t, u, v);
        } else if constexpr (TM == TriangleMethod::Watertight) {
            return intersect_triangle_watertight<F>(active, r.watertight, r.tnear, tfar, p0, a, c, t, u, v);
        } else {
            return intersect_triangle_plane<F>(active, r.org, r.dir, r.tnear, tfar, p0, a, c, t, u, v);
        }
    }

    /// Triangle `index` of the scene's triangles against one ray (T float or
    /// double); t, u, v change only on a hit.
    template <class T>
    static bool intersect(const Scene& scene, std::uint32_t index, const KernelChoice& k, const Ray<T>& ray, T& t,
                          T& u, T& v) {
        const TriangleSoA& tr = scene.triangles;
        return intersect_triangle(k.triangle, ray, Vec3<T>(tr.p0[index]), Vec3<T>(tr.p1[index]),
                                  Vec3<T>(tr.p2[index]), t, u, v);
    }

    /// Triangle `index` against the lanes `valid` of a packet.
    template <class F>
    static RAYPACK_INLINE mask_of<F> intersect(const Scene& scene, std::uint32_t index, const KernelChoice& k,
                                               mask_of<F> valid, const RayLanes<F>& ray, F& t, F& u, F& v) {
        const TriangleSoA& tr = scene.triangles;
        const Vec3<F> p0 = splat<F>(tr.p0[index]), p1 = splat<F>(tr.p1[index]), p2 = splat<F>(tr.p2[index]);
        switch (k.triangle) {
            case TriangleMethod::Moeller:
                return intersect_triangle_moeller(valid, ray.org, ray.dir, ray.tnear, ray.tfar, p0, p1, p2, t, u, v);
            case TriangleMethod::Plane:
                return intersect_triangle_plane(valid, ray.org, ray.dir, ray.tnear, ray.tfar, p0, p1, p2, t, u, v);
            default: break;
        }
        return intersect_triangle_watertight(valid, ray.org, ray.dir, ray.tnear, ray.tfar, p0, p1, p2, t, u, v);
    }
};

}  // namespace raypack
