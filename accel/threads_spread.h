#pragma once
// Threads of a parallel loop spread over the CPUs, one each.
#include <sched.h>

#include <atomic>
#include <thread>
#include <vector>

namespace raypack {

/// Puts each thread of one parallel loop (oneTBB) on a CPU of its own,
/// among those the caller may run on, the caller on the one it is on: make
/// one before the loop and call enter() at the start of each task. The
/// caller gets its affinity back when this ends; TBB's workers keep theirs
/// until the next loop pins them again. Left to the kernel, the woken
/// worker was mostly placed on the waking thread's CPU and left there for
/// the whole of a short loop: both threads shared one CPU (sched_getcpu per
/// task), and two threads rendered tetra (8 ms) and traced its camera rays
/// no faster than one (docs/renderer.md, "Two threads"). TBB's workers
/// that have joined the arena before are pinned before the loop starts, so
/// that the kernel wakes each on its own CPU: pinned only once running,
/// a worker woken on the caller's CPU waited there for it (0.5-5 ms into a
/// 5 ms render).
class ThreadsSpread {
public:
    ThreadsSpread();
    ~ThreadsSpread();
    ThreadsSpread(const ThreadsSpread&) = delete;
    ThreadsSpread& operator=(const ThreadsSpread&) = delete;

    /// Pins the calling thread the first time it comes.
    void enter();

    /// Lets TBB's workers run a task now, without waiting for them, so
    /// that the first loop finds them known, on the CPUs it will want and
    /// with their stacks mapped (call early, e.g. before a scene loads).
    /// Nothing at one thread.
    static void start_workers();

    /// Threads a parallel loop may run on now: the arena's concurrency
    /// within the limit of a tbb::global_control (`--threads`), which
    /// this_task_arena::max_concurrency() does not reflect.
    static int threads();

private:
    std::thread::id caller_ = std::this_thread::get_id();
    bool caller_pinned_ = false;
    std::atomic<std::size_t> next_cpu_{1};
    cpu_set_t caller_mask_{};
    std::vector<int> cpus_;     ///< the caller's CPUs, its current one first
    std::vector<char> pinned_;  ///< per worker slot
    std::vector<int> worker_tids_;  ///< the workers pinned before the loop
};

}  // namespace raypack
