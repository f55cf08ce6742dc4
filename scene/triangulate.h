#pragma once
// Triangulation of one planar (or nearly planar) polygon given by its vertex
// loop, as used by the NFF "p"/"pp" and OBJ "f" entities.
#include <array>
#include <cstdint>
#include <span>
#include <vector>

#include "kernels/vec3.h"

namespace raypack {

/// Triangles as index triples into `verts`, always exactly n-2 of them for
/// n >= 3 vertices (none for n < 3). Each triangle keeps the polygon's winding,
/// so its geometric normal faces the same way as the polygon's Newell normal.
/// A convex quadrilateral becomes the fan (0,1,2), (0,2,3); larger or
/// concave polygons are cut by ear clipping in passes round the loop (every
/// other corner per pass: triangles of comparable size, no fan of slivers
/// from one vertex). Collinear and duplicate vertices give zero-area triangles; a
/// polygon ear clipping cannot cut (self-intersecting, or a zero Newell
/// normal) finishes as a fan, so the count is still n-2.
std::vector<std::array<std::uint32_t, 3>> triangulate_polygon(std::span<const Vec3f> verts);

}  // namespace raypack
