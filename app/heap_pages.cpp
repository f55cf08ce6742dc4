#include "app/heap_pages.h"

#include <malloc.h>
#include <sys/mman.h>
#include <unistd.h>

#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <new>

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

#ifndef RAYPACK_ASAN
/// Blocks this large get huge pages where they span whole ones.
constexpr std::size_t kHugeAdviceMin = std::size_t(4) << 20;

/// Asks for transparent huge pages on the whole 2 MiB pages inside a fresh
/// block, before anything touches it: glibc.malloc.hugetlb=1 does the same
/// inside malloc, but only when set in the environment at start-up.
void advise_huge_pages(void* p, std::size_t bytes) {
    if (bytes < kHugeAdviceMin) return;
    const auto begin = reinterpret_cast<std::uintptr_t>(p);
    const std::uintptr_t lo = (begin + kHugePage - 1) & ~(kHugePage - 1), hi = (begin + bytes) & ~(kHugePage - 1);
    if (hi > lo) madvise(reinterpret_cast<void*>(lo), hi - lo, MADV_HUGEPAGE);
}

/// Faults in a fresh block's pages with one call (MADV_POPULATE_WRITE,
/// Linux 5.14; older kernels refuse it and the pages fault in one by one as
/// before). A page fault costs about 11 us on this project's virtual
/// machines: 12 MiB touched page by page took 34 ms, populated 2 ms. Pages
/// the heap already holds cost a page-table walk. Blocks above 256 MiB are
/// left alone: a large reservation need not be used, and populating it
/// would commit all of it.
void populate(void* p, std::size_t bytes) {
    constexpr std::size_t kPopulateMin = std::size_t(256) << 10, kPopulateMax = std::size_t(256) << 20;
    if (bytes < kPopulateMin || bytes > kPopulateMax) return;
    const std::uintptr_t page = std::uintptr_t(sysconf(_SC_PAGESIZE));
    const auto begin = reinterpret_cast<std::uintptr_t>(p);
    const std::uintptr_t lo = (begin + page - 1) & ~(page - 1), hi = (begin + bytes) & ~(page - 1);
#ifdef MADV_POPULATE_WRITE
    if (hi > lo) madvise(reinterpret_cast<void*>(lo), hi - lo, MADV_POPULATE_WRITE);
#endif
}

void* allocate(std::size_t bytes, std::size_t alignment) {
    for (;;) {
        // A request of 0 bytes still gets a unique pointer ([basic.stc.dynamic.allocation]).
        const std::size_t size = bytes ? bytes : 1;
        void* p = alignment <= alignof(std::max_align_t)
                      ? std::malloc(size)
                      : std::aligned_alloc(alignment, (size + alignment - 1) / alignment * alignment);
        if (p) {
            advise_huge_pages(p, bytes);
            populate(p, bytes);
            return p;
        }
        std::new_handler handler = std::get_new_handler();
        if (!handler) throw std::bad_alloc();
        handler();
    }
}
#endif

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
    // One arena for every thread: glibc gives each new thread an arena of
    // its own, whose fresh pages (no huge pages, not populated) fault in one
    // by one as a render's worker grows its scratch memory, which the main
    // thread, on the heap prepared below, does not pay. At 2 threads with
    // tiles of 64, balls rendered in 47 ms with an arena per thread and 41
    // with one (1,500 fewer page faults); tetra (4 ms) about 4% slower.
    // The parallel loops allocate little (their scratch is reused), and
    // small blocks come from each thread's cache (tcache) without the
    // arena's lock.
    mallopt(M_ARENA_MAX, 1);
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

#ifndef RAYPACK_ASAN
// The replaceable global allocation functions ([new.delete]): every `new`
// of the program (the scene's and the structures' arrays, the NFF text) goes
// through malloc as before, and blocks of 4 MiB and more are advised to use
// huge pages. On this project's virtual machines a page fault costs several
// microseconds: building a BVH4 over 8.4 million triangles (gen:mount:11)
// spent more time faulting its fresh arrays in than building (docs/
// embree.md, "At a million triangles and more"). The deallocation functions
// stay the library's (free).
void* operator new(std::size_t bytes) { return raypack::app::allocate(bytes, 0); }
void* operator new[](std::size_t bytes) { return raypack::app::allocate(bytes, 0); }
void* operator new(std::size_t bytes, std::align_val_t a) { return raypack::app::allocate(bytes, std::size_t(a)); }
void* operator new[](std::size_t bytes, std::align_val_t a) { return raypack::app::allocate(bytes, std::size_t(a)); }
#endif
