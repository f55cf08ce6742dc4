#pragma once
// Refusing work that would need more memory than the machine has, with a
// clear message, before allocating (rather than being killed by the kernel).
#include <cstdint>
#include <string>

namespace raypack {

/// Bytes the system can give this process now: MemAvailable from
/// /proc/meminfo, else the physical memory; 0 when neither is known.
std::uint64_t available_memory();

/// Throws std::runtime_error "WHAT needs N MiB, more than the M MiB
/// available" when `bytes` exceeds available_memory() (unless unknown).
void require_memory(std::uint64_t bytes, const std::string& what);

}  // namespace raypack
