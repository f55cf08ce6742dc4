// The .rays and .hits readers on arbitrary bytes (the first byte picks the
// reader), through a file as the command line reads them.
#include <cstddef>
#include <cstdint>
#include <fstream>
#include <stdexcept>
#include <string>

#include <unistd.h>

#include "scene/ray_file.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    if (size == 0) return 0;
    static const std::string path = "/tmp/raypack_fuzz_" + std::to_string(::getpid()) + ".bin";
    {
        std::ofstream out(path, std::ios::binary | std::ios::trunc);
        out.write(reinterpret_cast<const char*>(data + 1), std::streamsize(size - 1));
    }
    try {
        if (data[0] & 1) raypack::read_hits(path);
        else raypack::read_rays(path);
    } catch (const std::runtime_error&) {
    }
    return 0;
}
