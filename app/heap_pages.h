#pragma once
// Process-wide heap settings for the command line (app/heap_pages.cpp).

namespace raypack::app {

/// Keeps large allocations on the heap, never returns freed heap memory to
/// the system, and backs the first HeapReserve bytes of the heap with
/// transparent huge pages where the kernel offers them (madvise mode).
/// Call once, first thing in main; a no-op under AddressSanitizer.
void reserve_heap_in_large_pages();

}  // namespace raypack::app
