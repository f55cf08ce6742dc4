#include "app/heap_pages.h"

#include <malloc.h>
#include <sys/mman.h>
#include <unistd.h>

#include <cstdint>
#include <cstdlib>

namespace raypack::app {
namespace {

#if defined(__has_feature)
#if __has_feature(address_sanitizer)
#define RAYPACK_ASAN 1
#endif
#endif
#if defined(__SANITIZE_ADDRESS__)
#define RAYPACK_ASAN 1
#endif

/// Heap address space set aside at start-up (untouched pages cost nothing).
constexpr std::size_t kHeapReserve = std::size_t(512) << 20;
constexpr std::uintptr_t kHugePage = std::uintptr_t(2) << 20;

}  // namespace

void reserve_heap_in_large_pages() {
#ifndef RAYPACK_ASAN
    // A render allocates and frees its large arrays (file text, scene,
    // build references, tree, image) once each. glibc serves blocks over
    // 128 KiB with fresh mmap'ed pages and unmaps them on free, so every
    // such array faults in page by page: 6,200 faults for gears, a quarter
    // of its load and build time on a VM (docs/renderer.md). Blocks up to
    // 32 MiB (glibc's largest threshold) now come from the heap, which
    // keeps what is freed.
    mallopt(M_MMAP_THRESHOLD, 32 << 20);
    mallopt(M_TRIM_THRESHOLD, 1 << 30);
    // Grow the heap once by kHeapReserve and ask for huge pages there, as
    // Embree does for its BVH memory and as glibc's glibc.malloc.hugetlb=1
    // tunable would, without needing the environment variable.
    mallopt(M_TOP_PAD, int(kHeapReserve));
    const auto before = reinterpret_cast<std::uintptr_t>(sbrk(0));
    // Larger than any top chunk left by start-up; volatile, or the compiler
    // may drop the malloc/free pair.
    void* volatile probe = std::malloc(std::size_t(1) << 20);
    const auto after = reinterpret_cast<std::uintptr_t>(sbrk(0));
    std::free(probe);
    mallopt(M_TOP_PAD, 128 << 10);  // glibc's default
    const std::uintptr_t lo = (before + kHugePage - 1) & ~(kHugePage - 1), hi = after & ~(kHugePage - 1);
    if (before != std::uintptr_t(-1) && hi > lo) madvise(reinterpret_cast<void*>(lo), hi - lo, MADV_HUGEPAGE);
#endif
}

}  // namespace raypack::app
