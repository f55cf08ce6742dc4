// The OBJ reader (tinyobjloader and raypack's checks) on arbitrary bytes,
// through a file as the command line reads it.
#include <cstddef>
#include <cstdint>
#include <fstream>
#include <string>

#include <unistd.h>

#include "scene/load.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    static const std::string path = "/tmp/raypack_fuzz_" + std::to_string(::getpid()) + ".obj";
    {
        std::ofstream out(path, std::ios::binary | std::ios::trunc);
        out.write(reinterpret_cast<const char*>(data), std::streamsize(size));
    }
    try {
        raypack::load_obj_file(path);
    } catch (const raypack::SceneError&) {
    }
    return 0;
}
