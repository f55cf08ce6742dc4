#pragma once
// The image cut into square tiles, rendered in parallel by oneTBB, and the
// order of pixels inside a tile: 4 x 4 blocks, so that each packet of up to
// 16 consecutive eye rays covers a compact patch of the image.
#include <atomic>
#include <cstdint>
#include <functional>
#include <memory>
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
    /// Tile `index` as the pixels [x0, x1) x [y0, y1).
    struct Rect {
        int x0, y0, x1, y1;
    };
    Rect rect(int index) const;
};

/// Calls `render_tile(index, slot)` for every tile, in parallel; `slot` is
/// the calling worker's number in [0, worker_slots()), so that each worker
/// can keep its own scratch memory and counters.
void for_each_tile(const TileGrid& grid, const std::function<void(int tile, int slot)>& render_tile);

/// Upper bound of the slots for_each_tile passes (the TBB arena's workers).
int worker_slots();

/// One scratch object per worker slot of for_each_tile, made on first use,
/// so that each worker reuses its memory and keeps its own counters.
template <class T>
class PerWorker {
public:
    PerWorker() : items_(static_cast<std::size_t>(worker_slots())) {}
    T& at(int slot) {
        auto& p = items_[std::size_t(slot)];
        if (!p) p = std::make_unique<Padded>();
        return p->value;
    }
    template <class F>
    void for_each(F f) const {
        for (const auto& p : items_)
            if (p) f(p->value);
    }

private:
    /// Each worker's object on cache lines of its own: the threads share
    /// one heap (app/heap_pages.cpp), where two objects made one after the
    /// other would share a line, and the counters in them are written per ray.
    struct alignas(64) Padded {
        T value;
    };
    std::vector<std::unique_ptr<Padded>> items_;
};

/// Pixels finished so far, reported to an optional callback after each tile.
class TileProgress {
public:
    using Callback = void (*)(void* context, std::uint64_t pixels_done, std::uint64_t pixels_total);
    TileProgress(std::uint64_t total, Callback callback, void* context)
        : total_(total), callback_(callback), context_(context) {}
    void add(std::uint64_t pixels) {
        const std::uint64_t done = done_.fetch_add(pixels, std::memory_order_relaxed) + pixels;
        if (callback_) callback_(context_, done, total_);
    }
    std::uint64_t total() const { return total_; }

private:
    std::atomic<std::uint64_t> done_{0};
    std::uint64_t total_;
    Callback callback_;
    void* context_;
};

}  // namespace raypack
