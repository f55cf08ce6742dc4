// The tiles of a render: the pixel order inside a tile, and the threads
// for_each_tile runs them on.
#include <gtest/gtest.h>
#include <sched.h>
#include <tbb/blocked_range.h>
#include <tbb/global_control.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <chrono>
#include <cstring>
#include <mutex>
#include <set>
#include <vector>

#include "accel/threads_spread.h"
#include "render/tiles.h"

namespace raypack {
namespace {

TEST(Tiles, PixelsCoverTheTileInBlocksOfFour) {
    const TileGrid grid{21, 10, 8};  // partial tiles on the right and at the bottom
    ASSERT_EQ(grid.count(), 3 * 2);
    std::set<std::pair<int, int>> seen;
    std::vector<PixelXY> px;
    for (int t = 0; t < grid.count(); ++t) {
        grid.pixels(t, px);
        for (const PixelXY& p : px) EXPECT_TRUE(seen.insert({p.x, p.y}).second) << p.x << ", " << p.y;
    }
    EXPECT_EQ(seen.size(), 21u * 10u);
    grid.pixels(0, px);  // a full tile: 4 x 4 blocks, each row-major
    ASSERT_EQ(px.size(), 64u);
    for (int i = 0; i < 16; ++i) EXPECT_EQ(px[std::size_t(i)].x, i % 4) << i;
    EXPECT_EQ(px[16].x, 4);
    EXPECT_EQ(px[16].y, 0);
}

// With two threads and two CPUs allowed, each thread of the loop keeps one
// CPU of its own for the whole loop (a woken worker left on its waker's CPU
// halved both), and the caller gets its affinity back afterwards.
TEST(Tiles, ThreadsRunOnCpusOfTheirOwn) {
    cpu_set_t before;
    ASSERT_EQ(sched_getaffinity(0, sizeof before, &before), 0);
    if (CPU_COUNT(&before) < 2) GTEST_SKIP() << "one CPU allowed";
    tbb::global_control two(tbb::global_control::max_allowed_parallelism, 2);
    std::mutex m;
    std::vector<std::set<int>> cpus(static_cast<std::size_t>(worker_slots()));
    bool both = false;
    for (int attempt = 0; attempt < 20 && !both; ++attempt) {
        for (auto& c : cpus) c.clear();
        const TileGrid grid{64 * 16, 16, 16};
        for_each_tile(grid, [&](int, int slot) {
            // Long enough tiles that the worker joins in.
            const auto end = std::chrono::steady_clock::now() + std::chrono::microseconds(200);
            while (std::chrono::steady_clock::now() < end) {
            }
            std::lock_guard lock(m);
            cpus.at(std::size_t(slot)).insert(sched_getcpu());
        });
        int slots_used = 0;
        std::set<int> all;
        for (const auto& c : cpus) {
            if (c.empty()) continue;
            ++slots_used;
            EXPECT_EQ(c.size(), 1u) << "a thread moved between CPUs";
            all.insert(c.begin(), c.end());
        }
        both = slots_used == 2;
        if (both) {
            EXPECT_EQ(all.size(), 2u) << "two threads shared a CPU";
        }
    }
    EXPECT_TRUE(both) << "the worker never took a tile";
    cpu_set_t after;
    ASSERT_EQ(sched_getaffinity(0, sizeof after, &after), 0);
    EXPECT_TRUE(CPU_EQUAL(&before, &after));
}

// Under `--threads 1` (a global_control of one thread) every tile runs on
// the caller, also after start_workers: its enqueued tasks woke a worker
// anyway (TBB's mandatory concurrency), which took part in a quarter of the
// one-thread renders.
TEST(Tiles, OneThreadMeansOneThread) {
    tbb::global_control one(tbb::global_control::max_allowed_parallelism, 1);
    EXPECT_EQ(ThreadsSpread::threads(), 1);
    std::mutex m;
    std::set<int> slots;
    for (int attempt = 0; attempt < 10; ++attempt) {
        ThreadsSpread::start_workers();
        for_each_tile(TileGrid{32 * 16, 16, 16}, [&](int, int slot) {
            const auto end = std::chrono::steady_clock::now() + std::chrono::microseconds(100);
            while (std::chrono::steady_clock::now() < end) {
            }
            std::lock_guard lock(m);
            slots.insert(slot);
        });
    }
    EXPECT_EQ(slots, std::set<int>{0});
}

// A worker that has joined the arena before is already on a CPU of its own,
// not the caller's, when it starts its first task of a loop: pinned by
// ThreadsSpread before the loop wakes it, not by enter() once running.
TEST(Tiles, KnownWorkersArePinnedBeforeTheLoopWakesThem) {
    cpu_set_t all;
    ASSERT_EQ(sched_getaffinity(0, sizeof all, &all), 0);
    if (CPU_COUNT(&all) < 2) GTEST_SKIP() << "one CPU allowed";
    tbb::global_control two(tbb::global_control::max_allowed_parallelism, 2);
    ThreadsSpread::start_workers();
    // Until the worker has run a task of a spread loop (which makes it
    // known): each task then unpins its thread, so that only a pin made
    // before the next loop can hold.
    const auto spin = [] {
        const auto end = std::chrono::steady_clock::now() + std::chrono::microseconds(200);
        while (std::chrono::steady_clock::now() < end) {
        }
    };
    bool worker_ran = false;
    for (int attempt = 0; attempt < 50 && !worker_ran; ++attempt) {
        ThreadsSpread known;
        tbb::parallel_for(tbb::blocked_range<int>(0, 64, 1), [&](const tbb::blocked_range<int>&) {
            known.enter();
            sched_setaffinity(0, sizeof all, &all);
            spin();
            if (tbb::this_task_arena::current_thread_index() != 0) worker_ran = true;  // a bool set, never cleared
        });
    }
    ASSERT_TRUE(worker_ran) << "the worker never took a task";
    std::mutex m;
    bool checked = false;
    {
        ThreadsSpread spread;
        const int caller_cpu = sched_getcpu();
        tbb::parallel_for(tbb::blocked_range<int>(0, 64, 1), [&](const tbb::blocked_range<int>&) {
            if (tbb::this_task_arena::current_thread_index() != 0) {
                cpu_set_t now;
                ASSERT_EQ(sched_getaffinity(0, sizeof now, &now), 0);
                const std::lock_guard lock(m);
                if (!checked) {
                    EXPECT_EQ(CPU_COUNT(&now), 1) << "the worker was not pinned before its first task";
                    EXPECT_FALSE(CPU_ISSET(caller_cpu, &now)) << "the worker was pinned to the caller's CPU";
                    checked = true;
                }
            }
            spread.enter();
            spin();
        });
    }
    if (!checked) GTEST_SKIP() << "the worker took no task of the loop";
}

}  // namespace
}  // namespace raypack
