#pragma once
// Process-wide heap settings for the command line (app/heap_pages.cpp).

namespace raypack::app {

/// Keeps blocks up to 32 MiB on the heap, keeps freed heap memory (up to
/// 1 GiB) instead of returning it to the system, and backs the first 512 MiB
/// of the heap with transparent huge pages where the kernel offers them
/// (its "madvise" mode).
/// Call once, first thing in main; a no-op under AddressSanitizer.
void reserve_heap_in_large_pages();

}  // namespace raypack::app
