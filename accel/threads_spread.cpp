#include "accel/threads_spread.h"

#include <sys/stat.h>
#include <unistd.h>
#include <tbb/global_control.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <mutex>
#include <string>

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
/// could have left its id to another process's thread).
bool own_thread(int tid) {
    struct stat st {};
    return ::stat(("/proc/self/task/" + std::to_string(tid)).c_str(), &st) == 0;
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
    for (int k = 1; k < slots; ++k)
        tbb::this_task_arena::enqueue([] {
            if (tbb::this_task_arena::current_thread_index() > 0) workers().add(int(gettid()));
        });
}

ThreadsSpread::ThreadsSpread() {
    const int slots = tbb::this_task_arena::max_concurrency();
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
    // The known workers, each on the next CPU after the caller's, before
    // the loop wakes them.
    for (const int tid : workers().tids()) {
        if (worker_tids_.size() + 1 >= std::size_t(slots) || !own_thread(tid)) continue;
        cpu_set_t one;
        CPU_ZERO(&one);
        CPU_SET(cpus_[next_cpu_.fetch_add(1, std::memory_order_relaxed) % cpus_.size()], &one);
        if (sched_setaffinity(tid, sizeof one, &one) == 0) worker_tids_.push_back(tid);
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
