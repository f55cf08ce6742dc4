#pragma once
// Parallel construction of a uniform grid by a counting sort of primitive
// references into cells (count pass, prefix sum, fill pass), as in Kalojanov
// & Slusallek, "A Parallel Algorithm for Construction of Uniform Grids", HPG
// 2009, and Lagae & Dutre 2008.
#include <span>

#include "accel/grid/grid.h"
#include "accel/grid/primitive_box_overlap.h"

namespace raypack {

/// Grid over primitives 0 .. boxes.size() - 1. A primitive goes into every
/// cell its bounding box meets and, if `exact` is given, that `exact` says it
/// overlaps. Cells are widened by grid_placement_margin() for this test, so
/// that a hit the ray-primitive kernels report within rounding error of a
/// cell is found in that cell. Primitives with a non-finite or empty box are
/// left out.
Grid build_grid(std::span<const Box3f> boxes, const PrimitiveBoxOverlap* exact, const GridConfig& config);

/// grid.macro from grid's cells (its shift as set).
void build_macrocells(Grid& grid);

/// Margin by which cells are widened when primitives are placed: 1e-5 of the
/// grid's largest extent, plus 8 ulps of its largest coordinate. It covers the
/// rounding of the DDA (a few ulps of t) for ray origins up to ~20 grid sizes
/// away, and of the primitive kernels near cell planes.
float grid_placement_margin(const Box3f& bounds);

}  // namespace raypack
