#include "render/tiles.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <algorithm>

#include "accel/threads_spread.h"

namespace raypack {

TileGrid::Rect TileGrid::rect(int index) const {
    const int x0 = (index % tiles_x()) * tile, y0 = (index / tiles_x()) * tile;
    return {x0, y0, std::min(x0 + tile, width), std::min(y0 + tile, height)};
}

void TileGrid::pixels(int index, std::vector<PixelXY>& out) const {
    constexpr int kBlock = 4;
    out.clear();
    const auto [x0, y0, x1, y1] = rect(index);
    for (int by = y0; by < y1; by += kBlock)
        for (int bx = x0; bx < x1; bx += kBlock)
            for (int y = by; y < std::min(by + kBlock, y1); ++y)
                for (int x = bx; x < std::min(bx + kBlock, x1); ++x) out.push_back({x, y});
}

int worker_slots() { return tbb::this_task_arena::max_concurrency(); }

void for_each_tile(const TileGrid& grid, const std::function<void(int tile, int slot)>& render_tile) {
    ThreadsSpread spread;
    // One tile per task: tiles cost very different amounts (sky against
    // glass), and a tile is thousands of rays, so scheduling is cheap.
    tbb::parallel_for(tbb::blocked_range<int>(0, grid.count(), 1), [&](const tbb::blocked_range<int>& r) {
        const int slot = tbb::this_task_arena::current_thread_index();
        spread.enter();
        for (int t = r.begin(); t < r.end(); ++t) render_tile(t, slot);
    });
}

}  // namespace raypack
