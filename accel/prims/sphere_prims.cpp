#include "accel/prims/sphere_prims.h"

#include <cassert>

namespace raypack {

template <int M>
void SpherePrims::pack(Block<M>& block, std::span<const std::uint32_t> prims, const Scene& scene,
                       const BlockLayout&) {
    assert(prims.size() <= std::size_t(M));
    fill_rows(block.center, kBlockPadding);
    for (int j = 0; j < M; ++j) {
        block.radius[j] = kBlockPadding;
        block.prim[j] = kNoPrim;
    }
    for (std::size_t j = 0; j < prims.size(); ++j) {
        const std::uint32_t i = scene.prims[prims[j]].index;
        block.prim[j] = prims[j];
        set_row(block.center, int(j), scene.spheres.center[i]);
        block.radius[j] = scene.spheres.radius[i];
    }
}

template void SpherePrims::pack<4>(Block<4>&, std::span<const std::uint32_t>, const Scene&, const BlockLayout&);
template void SpherePrims::pack<8>(Block<8>&, std::span<const std::uint32_t>, const Scene&, const BlockLayout&);

}  // namespace raypack
