// The OBJ reader (scene/obj_loader.cpp) on arbitrary bytes, in
// memory: load_obj_file reads the file and calls the same load_obj_text.
#include <cstddef>
#include <cstdint>
#include <string_view>

#include "scene/load.h"
#include "scene/nff_text.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    try {
        raypack::load_obj_text(std::string_view(reinterpret_cast<const char*>(data), size), "fuzz.obj");
    } catch (const raypack::SceneError&) {
    }
    return 0;
}
