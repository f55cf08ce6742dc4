// The tiles of a render: the pixel order inside a tile, and the threads
// for_each_tile runs them on.
#include <gtest/gtest.h>
#include <sched.h>
#include <tbb/global_control.h>

#include <chrono>
#include <cstring>
#include <mutex>
#include <set>
#include <vector>

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

}  // namespace
}  // namespace raypack
