#include "accel/threads_spread.h"

#include <sys/mman.h>
#include <sys/syscall.h>
#include <unistd.h>
#include <tbb/global_control.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <atomic>
#include <cstdint>
#include <memory>
#include <mutex>

namespace raypack {

namespace {

/// The thread ids of TBB's workers that have run a task of a spread loop
/// or of start_workers (they stay in TBB's pool once made). Recorded from
/// the tasks themselves: a task_scheduler_observer's registration leaked
/// at exit (LeakSanitizer).
class Workers {
public:
    void add(int tid) {
        const std::lock_guard<std::mutex> lock(mutex_);
        if (std::find(tids_.begin(), tids_.end(), tid) == tids_.end()) tids_.push_back(tid);
    }
    std::vector<int> tids() {
        const std::lock_guard<std::mutex> lock(mutex_);
        return tids_;
    }

private:
    std::mutex mutex_;
    std::vector<int> tids_;
};

Workers& workers() {
    static Workers w;
    return w;
}

/// Whether thread `tid` is one of this process's (a worker TBB ended
/// could have left its id to another process's thread): signal 0 to a
/// thread of this thread group checks that it exists and sends nothing
/// (tgkill(2); a stat of /proc/self/task/TID took 0.1 ms).
bool own_thread(int tid) { return syscall(SYS_tgkill, getpid(), tid, 0) == 0; }

/// The CPUs of `mask`, the calling thread's current one first.
std::vector<int> cpus_from_here(const cpu_set_t& mask) {
    std::vector<int> cpus;
    for (int c = 0; c < CPU_SETSIZE; ++c)
        if (CPU_ISSET(c, &mask)) cpus.push_back(c);
    const auto here = std::find(cpus.begin(), cpus.end(), sched_getcpu());
    if (here != cpus.end()) std::rotate(cpus.begin(), here, cpus.end());
    return cpus;
}

/// Stack a render's deepest calls use (the traversals' stacks of packets
/// and nodes): 108 KiB on a worker thread rendering tetra.
constexpr std::size_t kWarmStackBytes = std::size_t(256) << 10;

/// Maps the calling thread's stack pages down to the depth a render
/// reaches, in one call: a TBB worker's stack is fresh memory, whose pages
/// otherwise fault in one by one (a few microseconds each on a virtual
/// machine) on the thread's first tiles.
[[gnu::noinline]] void warm_stack() {
    alignas(64) char frame[kWarmStackBytes];
    volatile char* const far_end = frame;
    *far_end = 0;
    const std::uintptr_t page = std::uintptr_t(sysconf(_SC_PAGESIZE));
    const auto lo = (reinterpret_cast<std::uintptr_t>(frame) + page - 1) & ~(page - 1);
    const auto hi = (reinterpret_cast<std::uintptr_t>(frame) + sizeof frame) & ~(page - 1);
#ifdef MADV_POPULATE_WRITE
    if (hi > lo && madvise(reinterpret_cast<void*>(lo), hi - lo, MADV_POPULATE_WRITE) == 0) return;
#endif
    for (std::uintptr_t a = lo; a < hi; a += page) *reinterpret_cast<volatile char*>(a) = 0;
}

}  // namespace

int ThreadsSpread::threads() {
    const std::size_t limit = tbb::global_control::active_value(tbb::global_control::max_allowed_parallelism);
    return int(std::min<std::size_t>(std::size_t(tbb::this_task_arena::max_concurrency()), limit));
}

void ThreadsSpread::start_workers() {
    workers();
    // Under a limit of one thread, an enqueued task still wakes a worker
    // (TBB's mandatory concurrency), which then took part in a quarter of
    // the `--threads 1` renders.
    const int slots = threads();
    if (slots < 2) return;
    // Each worker pins itself where the first loop will want it (the CPUs
    // after the caller's, as ThreadsSpread places them), so that the loop
    // need not move it.
    cpu_set_t mask;
    std::vector<int> cpus;
    if (sched_getaffinity(0, sizeof mask, &mask) == 0) cpus = cpus_from_here(mask);
    const auto next = std::make_shared<std::atomic<std::size_t>>(1);
    for (int k = 1; k < slots; ++k)
        tbb::this_task_arena::enqueue([cpus, next] {
            if (tbb::this_task_arena::current_thread_index() == 0) return;
            if (cpus.size() >= 2) {
                cpu_set_t one;
                CPU_ZERO(&one);
                CPU_SET(cpus[next->fetch_add(1, std::memory_order_relaxed) % cpus.size()], &one);
                sched_setaffinity(0, sizeof one, &one);
            }
            workers().add(int(gettid()));
            // Faulted in page by page, the worker's stack cost a 2-thread
            // render of tetra 0.2-0.3 ms on the worker's first tiles.
            warm_stack();
        });
}

ThreadsSpread::ThreadsSpread() {
    const int slots = tbb::this_task_arena::max_concurrency();
    if (slots < 2 || sched_getaffinity(0, sizeof caller_mask_, &caller_mask_) != 0) return;
    cpus_ = cpus_from_here(caller_mask_);
    if (cpus_.size() < 2) {
        cpus_.clear();
        return;
    }
    pinned_.assign(std::size_t(slots), 0);
    // The known workers, each on the next CPU after the caller's, before
    // the loop wakes them.
    for (const int tid : workers().tids()) {
        if (worker_tids_.size() + 1 >= std::size_t(slots) || !own_thread(tid)) continue;
        cpu_set_t one, now;
        CPU_ZERO(&one);
        CPU_SET(cpus_[next_cpu_.fetch_add(1, std::memory_order_relaxed) % cpus_.size()], &one);
        // Already there (start_workers or the last loop put it there): a
        // worker still spinning after a loop took 0.02-0.14 ms to move.
        const bool there = sched_getaffinity(tid, sizeof now, &now) == 0 && CPU_EQUAL(&now, &one);
        if (there || sched_setaffinity(tid, sizeof one, &one) == 0) worker_tids_.push_back(tid);
    }
}

ThreadsSpread::~ThreadsSpread() {
    if (caller_pinned_) sched_setaffinity(0, sizeof caller_mask_, &caller_mask_);
}

void ThreadsSpread::enter() {
    if (cpus_.empty()) return;
    const int slot = tbb::this_task_arena::current_thread_index();
    if (slot < 0 || std::size_t(slot) >= pinned_.size() || pinned_[std::size_t(slot)]) return;
    pinned_[std::size_t(slot)] = 1;  // each slot is written by its own thread only
    // The caller stays where it is; the others take the next CPUs (those
    // pinned before the loop have theirs).
    const bool caller = std::this_thread::get_id() == caller_;
    if (!caller) {
        const int tid = int(gettid());
        if (std::find(worker_tids_.begin(), worker_tids_.end(), tid) != worker_tids_.end()) return;
        workers().add(tid);  // known from now on: the next loop pins it before waking it
    }
    if (caller) caller_pinned_ = true;
    const std::size_t k = caller ? 0 : next_cpu_.fetch_add(1, std::memory_order_relaxed) % cpus_.size();
    cpu_set_t one;
    CPU_ZERO(&one);
    CPU_SET(cpus_[k], &one);
    sched_setaffinity(0, sizeof one, &one);  // the calling thread (Linux)
}

}  // namespace raypack
