#include "render/tiles.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <sched.h>

#include <algorithm>
#include <atomic>
#include <thread>
#include <vector>

namespace raypack {

void TileGrid::pixels(int index, std::vector<PixelXY>& out) const {
    constexpr int kBlock = 4;
    out.clear();
    const int x0 = (index % tiles_x()) * tile, y0 = (index / tiles_x()) * tile;
    const int x1 = std::min(x0 + tile, width), y1 = std::min(y0 + tile, height);
    for (int by = y0; by < y1; by += kBlock)
        for (int bx = x0; bx < x1; bx += kBlock)
            for (int y = by; y < std::min(by + kBlock, y1); ++y)
                for (int x = bx; x < std::min(bx + kBlock, x1); ++x) out.push_back({x, y});
}

int worker_slots() { return tbb::this_task_arena::max_concurrency(); }

namespace {

/// Puts each thread of one parallel loop on a CPU of its own, among those
/// the caller may run on, the caller on the one it is on. The caller gets
/// its affinity back at the end; TBB's workers keep theirs until the next
/// loop pins them again. Left to the kernel, the woken worker was mostly
/// placed on the waking thread's CPU and left there for the whole of a
/// short render: both threads shared one CPU (sched_getcpu per tile), and
/// two threads rendered tetra (8 ms) slower than one (docs/renderer.md,
/// "Two threads").
class ThreadsSpread {
public:
    ThreadsSpread() {
        const int slots = worker_slots();
        if (slots < 2 || sched_getaffinity(0, sizeof caller_mask_, &caller_mask_) != 0) return;
        for (int c = 0; c < CPU_SETSIZE; ++c)
            if (CPU_ISSET(c, &caller_mask_)) cpus_.push_back(c);
        if (cpus_.size() < 2) {
            cpus_.clear();
            return;
        }
        const auto here = std::find(cpus_.begin(), cpus_.end(), sched_getcpu());
        if (here != cpus_.end()) std::rotate(cpus_.begin(), here, cpus_.end());
        pinned_.assign(std::size_t(slots), 0);
    }
    ~ThreadsSpread() {
        if (caller_pinned_) sched_setaffinity(0, sizeof caller_mask_, &caller_mask_);
    }
    ThreadsSpread(const ThreadsSpread&) = delete;
    ThreadsSpread& operator=(const ThreadsSpread&) = delete;

    /// Pins the calling thread, worker slot `slot`, the first time it comes.
    void enter(int slot) {
        if (cpus_.empty() || slot < 0 || std::size_t(slot) >= pinned_.size() || pinned_[std::size_t(slot)]) return;
        pinned_[std::size_t(slot)] = 1;  // each slot is written by its own thread only
        // The caller stays where it is; the others take the next CPUs.
        const bool caller = std::this_thread::get_id() == caller_;
        if (caller) caller_pinned_ = true;
        const std::size_t k = caller ? 0 : next_cpu_.fetch_add(1, std::memory_order_relaxed) % cpus_.size();
        cpu_set_t one;
        CPU_ZERO(&one);
        CPU_SET(cpus_[k], &one);
        sched_setaffinity(0, sizeof one, &one);  // the calling thread (Linux)
    }

private:
    std::thread::id caller_ = std::this_thread::get_id();
    bool caller_pinned_ = false;
    std::atomic<std::size_t> next_cpu_{1};
    cpu_set_t caller_mask_{};
    std::vector<int> cpus_;    ///< the caller's CPUs, its current one first
    std::vector<char> pinned_;  ///< per worker slot
};

}  // namespace

void for_each_tile(const TileGrid& grid, const std::function<void(int tile, int slot)>& render_tile) {
    ThreadsSpread spread;
    // One tile per task: tiles cost very different amounts (sky against
    // glass), and a tile is thousands of rays, so scheduling is cheap.
    tbb::parallel_for(tbb::blocked_range<int>(0, grid.count(), 1), [&](const tbb::blocked_range<int>& r) {
        const int slot = tbb::this_task_arena::current_thread_index();
        spread.enter(slot);
        for (int t = r.begin(); t < r.end(); ++t) render_tile(t, slot);
    });
}

}  // namespace raypack
