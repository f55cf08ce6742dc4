#include "accel/prims/triangle_prims.h"

#include <cassert>

namespace raypack {

template <int M>
void TrianglePrims::pack(Block<M>& block, std::span<const std::uint32_t> prims, const Scene& scene,
                         const BlockLayout& layout) {
    assert(prims.size() <= std::size_t(M));
    for (auto* a : {&block.p0, &block.a, &block.b, &block.ng}) fill_rows(*a, kBlockPadding);
    for (std::uint32_t& p : block.prim) p = kNoPrim;
    const TriangleSoA& tr = scene.triangles;
    for (std::size_t j = 0; j < prims.size(); ++j) {
        const int lane = int(j);
        const std::uint32_t i = scene.prims[prims[j]].index;
        const Vec3f p0 = tr.p0[i], p1 = tr.p1[i], p2 = tr.p2[i];
        block.prim[lane] = prims[j];
        set_row(block.p0, lane, p0);
        if (layout.triangles == TriangleLayout::Edges) {
            const auto e = triangle_detail::moeller_edges(p0, p1, p2);  // what intersect_triangle_moeller computes
            set_row(block.a, lane, e.e1n);
            set_row(block.b, lane, e.e2);
            set_row(block.ng, lane, e.ng);
        } else {
            set_row(block.a, lane, p1);
            set_row(block.b, lane, p2);
        }
    }
}

template void TrianglePrims::pack<4>(Block<4>&, std::span<const std::uint32_t>, const Scene&, const BlockLayout&);
template void TrianglePrims::pack<8>(Block<8>&, std::span<const std::uint32_t>, const Scene&, const BlockLayout&);

}  // namespace raypack
