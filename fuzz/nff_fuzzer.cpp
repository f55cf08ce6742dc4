// The NFF reader, every keyword included, on arbitrary bytes: a SceneError
// is a fine answer; a crash, a leak or a sanitizer report is not.
#include <cstddef>
#include <cstdint>
#include <string_view>

#include "scene/load.h"
#include "scene/nff_text.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    try {
        raypack::load_nff_text(std::string_view(reinterpret_cast<const char*>(data), size), "fuzz.nff");
    } catch (const raypack::SceneError&) {
    }
    return 0;
}
