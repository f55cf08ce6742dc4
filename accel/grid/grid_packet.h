#pragma once
// Packet traversal of the uniform grid. Consecutive packets whose rays share
// a major direction walk the grid slice by slice, in groups of 128 rays
// (512 rays from one point in packets of 16; coherent_grid_group.h, Wald et
// al. 2006), or a packet at once
// (coherent_grid.h). Other packets step each lane's own 3D-DDA
// (dda_packet.h): lanes in empty cells step together, and a cell with
// references is tested once, with the packet kernels, for all the lanes that
// stand in it. The grid's primitives outside its cells (Grid::outside) are
// tested first.
#include <cstdint>
#include <span>

#include "accel/grid/grid.h"
#include "accel/primitive_intersector.h"
#include "kernels/ray.h"
#include "scene/scene.h"

namespace raypack {

/// True if packets of the grid can use the float counters of dda_packet.h.
bool grid_packets_exact(const Grid& grid);

/// Closest hits (AnyHit = false) or occlusion (AnyHit = true, hits[i].prim
/// = 0 where occluded) of `rays` in packets of K. `coherent`: packets whose
/// rays share a major direction walk slice by slice (coherent_grid*.h; the
/// single-ray walk's answers, ties between primitives at the same t aside);
/// the others, or all if not `coherent`, step each lane's own DDA, with the
/// same answers as the single-ray walk without mailbox, bit for bit.
/// `triangle_edges`: the grid's triangle records (accel/prims/triangle_edges.h)
/// or null. Defined for the K that are compiled in (see kWidthCompiled).
template <int K, bool AnyHit>
void grid_trace_packets(const Grid& grid, const Scene& scene, KernelChoice kernels,
                        const TriangleEdgeRecord* triangle_edges, bool coherent,
                        std::span<const Rayf> rays, std::span<Hitf> hits);

}  // namespace raypack
