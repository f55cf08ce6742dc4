#include "accel/prims/height_field_prims.h"

#include <cassert>

namespace raypack {

template <int M>
void HeightFieldPrims::pack(Block<M>& block, std::span<const std::uint32_t> prims, const Scene& scene,
                            const BlockLayout&) {
    assert(prims.size() <= std::size_t(M));
    for (int j = 0; j < M; ++j) {
        block.field[j] = nullptr;
        block.prim[j] = kNoPrim;
    }
    for (std::size_t j = 0; j < prims.size(); ++j) {
        block.field[j] = &scene.height_fields[scene.prims[prims[j]].index];
        block.prim[j] = prims[j];
    }
}

template void HeightFieldPrims::pack<4>(Block<4>&, std::span<const std::uint32_t>, const Scene&, const BlockLayout&);
template void HeightFieldPrims::pack<8>(Block<8>&, std::span<const std::uint32_t>, const Scene&, const BlockLayout&);

}  // namespace raypack
