#include "accel/bvh/leaf_blocks.h"

#include <cassert>
#include <limits>

namespace raypack {
namespace {

constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();

template <int M>
void set3(float (&a)[3][M], int lane, const Vec3f& p) {
    a[0][lane] = p.x;
    a[1][lane] = p.y;
    a[2][lane] = p.z;
}

template <int M>
void fill3(float (&a)[3][M], float value) {
    for (auto& row : a)
        for (float& x : row) x = value;
}

}  // namespace

template <int M>
void pack_triangles(TriangleBlock<M>& block, std::span<const std::uint32_t> prims, const Scene& scene,
                    TriangleLayout layout) {
    assert(prims.size() <= std::size_t(M));
    for (auto* a : {&block.p0, &block.a, &block.b, &block.ng}) fill3(*a, kNaN);
    for (std::uint32_t& p : block.prim) p = kNoPrim;
    const TriangleSoA& tr = scene.triangles;
    for (std::size_t j = 0; j < prims.size(); ++j) {
        const int lane = int(j);
        const std::uint32_t i = scene.prims[prims[j]].index;
        const Vec3f p0 = tr.p0[i], p1 = tr.p1[i], p2 = tr.p2[i];
        block.prim[lane] = prims[j];
        set3(block.p0, lane, p0);
        if (layout == TriangleLayout::Edges) {
            const auto e = triangle_detail::moeller_edges(p0, p1, p2);  // what intersect_triangle_moeller computes
            set3(block.a, lane, e.e1n);
            set3(block.b, lane, e.e2);
            set3(block.ng, lane, e.ng);
        } else {
            set3(block.a, lane, p1);
            set3(block.b, lane, p2);
        }
    }
}

template <int M>
void pack_spheres(SphereBlock<M>& block, std::span<const std::uint32_t> prims, const Scene& scene) {
    assert(prims.size() <= std::size_t(M));
    fill3(block.center, kNaN);
    for (int j = 0; j < M; ++j) {
        block.radius[j] = kNaN;
        block.prim[j] = kNoPrim;
    }
    for (std::size_t j = 0; j < prims.size(); ++j) {
        const std::uint32_t i = scene.prims[prims[j]].index;
        block.prim[j] = prims[j];
        set3(block.center, int(j), scene.spheres.center[i]);
        block.radius[j] = scene.spheres.radius[i];
    }
}

template <int M>
void pack_cones(ConeBlock<M>& block, std::span<const std::uint32_t> prims, const Scene& scene) {
    assert(prims.size() <= std::size_t(M));
    for (auto* a : {&block.base, &block.w, &block.mid}) fill3(*a, kNaN);
    for (int j = 0; j < M; ++j) {
        block.h[j] = block.inv_h[j] = block.k[j] = block.rb[j] = kNaN;
        block.prim[j] = kNoPrim;
    }
    const ConeSoA& cs = scene.cones;
    for (std::size_t j = 0; j < prims.size(); ++j) {
        const int lane = int(j);
        const std::uint32_t i = scene.prims[prims[j]].index;
        // The scalar path calls make_cone per test; the same operations here.
        const ConeLanes<float> c = make_cone<float>(cs.base[i], cs.base_radius[i], cs.apex[i], cs.apex_radius[i]);
        block.prim[lane] = prims[j];
        set3(block.base, lane, c.base);
        set3(block.w, lane, c.w);
        set3(block.mid, lane, c.mid);
        block.h[lane] = c.h;
        block.inv_h[lane] = c.inv_h;
        block.k[lane] = c.k;
        block.rb[lane] = c.rb;
    }
}

template void pack_triangles<4>(TriangleBlock<4>&, std::span<const std::uint32_t>, const Scene&, TriangleLayout);
template void pack_triangles<8>(TriangleBlock<8>&, std::span<const std::uint32_t>, const Scene&, TriangleLayout);
template void pack_spheres<4>(SphereBlock<4>&, std::span<const std::uint32_t>, const Scene&);
template void pack_spheres<8>(SphereBlock<8>&, std::span<const std::uint32_t>, const Scene&);
template void pack_cones<4>(ConeBlock<4>&, std::span<const std::uint32_t>, const Scene&);
template void pack_cones<8>(ConeBlock<8>&, std::span<const std::uint32_t>, const Scene&);

}  // namespace raypack
