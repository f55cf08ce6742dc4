#include "accel/prims/cone_prims.h"

#include <cassert>

namespace raypack {

template <int M>
void ConePrims::pack(Block<M>& block, std::span<const std::uint32_t> prims, const Scene& scene, const BlockLayout&) {
    assert(prims.size() <= std::size_t(M));
    for (auto* a : {&block.base, &block.w, &block.mid}) fill_rows(*a, kBlockPadding);
    for (int j = 0; j < M; ++j) {
        block.h[j] = block.inv_h[j] = block.k[j] = block.rb[j] = kBlockPadding;
        block.prim[j] = kNoPrim;
    }
    const ConeSoA& cs = scene.cones;
    for (std::size_t j = 0; j < prims.size(); ++j) {
        const int lane = int(j);
        const std::uint32_t i = scene.prims[prims[j]].index;
        // The scalar path calls make_cone per test; the same operations here.
        const ConeLanes<float> c = make_cone<float>(cs.base[i], cs.base_radius[i], cs.apex[i], cs.apex_radius[i]);
        block.prim[lane] = prims[j];
        set_row(block.base, lane, c.base);
        set_row(block.w, lane, c.w);
        set_row(block.mid, lane, c.mid);
        block.h[lane] = c.h;
        block.inv_h[lane] = c.inv_h;
        block.k[lane] = c.k;
        block.rb[lane] = c.rb;
    }
}

template void ConePrims::pack<4>(Block<4>&, std::span<const std::uint32_t>, const Scene&, const BlockLayout&);
template void ConePrims::pack<8>(Block<8>&, std::span<const std::uint32_t>, const Scene&, const BlockLayout&);

}  // namespace raypack
