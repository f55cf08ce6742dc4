// The .rays and .hits readers on arbitrary bytes (the first byte picks the
// reader), in memory: read_rays/read_hits check a file's header, then parse
// its bytes with these same functions (tests/test_ray_file.cpp,
// BytesInMemoryReadAsTheFile).
#include <cstddef>
#include <cstdint>
#include <stdexcept>
#include <string_view>

#include "scene/ray_file.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    if (size == 0) return 0;
    const std::string_view bytes(reinterpret_cast<const char*>(data + 1), size - 1);
    try {
        if (data[0] & 1) raypack::parse_hits(bytes, "fuzz.hits");
        else raypack::parse_rays(bytes, "fuzz.rays");
    } catch (const std::runtime_error&) {
    }
    return 0;
}
