#pragma once
// The image cut into square tiles, rendered in parallel by oneTBB, and the
// order of pixels inside a tile: 4 x 4 blocks, so that each packet of up to
// 16 consecutive eye rays covers a compact patch of the image.
#include <cstdint>
#include <functional>
#include <vector>

namespace raypack {

struct PixelXY {
    int x, y;
};

struct TileGrid {
    int width = 0, height = 0, tile = 16;
    int tiles_x() const { return (width + tile - 1) / tile; }
    int tiles_y() const { return (height + tile - 1) / tile; }
    int count() const { return tiles_x() * tiles_y(); }
    /// Pixels of tile `index`, row-major over 4 x 4 blocks, each block row-major.
    void pixels(int index, std::vector<PixelXY>& out) const;
};

/// Calls `render_tile(index, slot)` for every tile, in parallel; `slot` is
/// the calling worker's number in [0, worker_slots()), so that each worker
/// can keep its own scratch memory and counters.
void for_each_tile(const TileGrid& grid, const std::function<void(int tile, int slot)>& render_tile);

/// Upper bound of the slots for_each_tile passes (the TBB arena's workers).
int worker_slots();

}  // namespace raypack
