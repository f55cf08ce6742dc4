#include "accel/threads_spread.h"

#include <tbb/task_arena.h>

#include <algorithm>

namespace raypack {

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
}

ThreadsSpread::~ThreadsSpread() {
    if (caller_pinned_) sched_setaffinity(0, sizeof caller_mask_, &caller_mask_);
}

void ThreadsSpread::enter() {
    if (cpus_.empty()) return;
    const int slot = tbb::this_task_arena::current_thread_index();
    if (slot < 0 || std::size_t(slot) >= pinned_.size() || pinned_[std::size_t(slot)]) return;
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

}  // namespace raypack
