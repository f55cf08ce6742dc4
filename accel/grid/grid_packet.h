#pragma once
// Packet traversal of the uniform grid: K rays, each lane stepping its own
// 3D-DDA (dda_packet.h). Lanes in empty cells step together; a cell with
// references is tested once, with the packet kernels, for all the lanes that
// stand in it, so coherent rays share their primitive tests.
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
/// = 0 where occluded) of `rays` in packets of K, with the same answers as
/// the single-ray walk without mailbox, bit for bit. Defined for the K that
/// are compiled in (see kWidthCompiled).
template <int K, bool AnyHit>
void grid_trace_packets(const Grid& grid, const Scene& scene, KernelChoice kernels, std::span<const Rayf> rays,
                        std::span<Hitf> hits);

}  // namespace raypack
