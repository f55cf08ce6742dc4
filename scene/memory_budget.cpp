#include "scene/memory_budget.h"

#include <fstream>
#include <sstream>
#include <stdexcept>

#include <unistd.h>

namespace raypack {

std::uint64_t available_memory() {
    std::ifstream in("/proc/meminfo");
    std::string key;
    std::uint64_t kib = 0;
    std::string unit;
    while (in >> key >> kib >> unit)
        if (key == "MemAvailable:") return kib * 1024;
    const long pages = ::sysconf(_SC_PHYS_PAGES), page = ::sysconf(_SC_PAGESIZE);
    return pages > 0 && page > 0 ? std::uint64_t(pages) * std::uint64_t(page) : 0;
}

void require_memory(std::uint64_t bytes, const std::string& what) {
    const std::uint64_t available = available_memory();
    if (available == 0 || bytes <= available) return;
    std::ostringstream msg;
    msg << what << " needs " << (bytes >> 20) << " MiB, more than the " << (available >> 20)
        << " MiB of memory available";
    throw std::runtime_error(msg.str());
}

}  // namespace raypack
