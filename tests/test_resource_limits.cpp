// Work that needs more memory than the machine has is refused up front
// with a message that says how much, and a ray file's header cannot claim
// more records than the file holds.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <stdexcept>
#include <string>

#include <unistd.h>

#include "scene/memory_budget.h"
#include "scene/ray_file.h"

namespace raypack {
namespace {

TEST(ResourceLimits, AvailableMemoryIsKnownAndBoundsRequests) {
    const std::uint64_t available = available_memory();
    ASSERT_GT(available, 0u);
    EXPECT_NO_THROW(require_memory(1 << 20, "a small buffer"));
    try {
        require_memory(available * 2, "a huge buffer");
        FAIL() << "no error for twice the available memory";
    } catch (const std::runtime_error& e) {
        const std::string msg = e.what();
        EXPECT_EQ(msg.rfind("a huge buffer needs ", 0), 0u) << msg;
        EXPECT_NE(msg.find("MiB of memory available"), std::string::npos) << msg;
    }
}

TEST(ResourceLimits, RayFileClaimingBillionsOfRaysIsRefusedBeforeReading) {
    const std::string path =
        (std::filesystem::temp_directory_path() / ("raypack_limits_" + std::to_string(::getpid()) + ".rays")).string();
    {
        std::ofstream out(path, std::ios::binary);
        const std::uint64_t count = 3'000'000'000ull;
        const std::uint32_t kind = 0, reserved = 0;
        out.write("RAYS0001", 8);
        out.write(reinterpret_cast<const char*>(&count), 8);
        out.write(reinterpret_cast<const char*>(&kind), 4);
        out.write(reinterpret_cast<const char*>(&reserved), 4);
        for (int i = 0; i < 8; ++i) out.write("\0\0\0\0", 4);  // one record
    }
    try {
        read_rays(path);
        FAIL() << "no error";
    } catch (const std::runtime_error& e) {
        EXPECT_NE(std::string(e.what()).find("3000000000 records"), std::string::npos) << e.what();
    }
    std::filesystem::remove(path);
}

}  // namespace
}  // namespace raypack
