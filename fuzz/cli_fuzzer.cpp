// The command-line parser: arbitrary argument lists (NUL-separated) against
// every command's option table. Only parsing: the options are read back as
// the commands read them, nothing is loaded or written.
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "app/commands.h"

namespace {

const std::vector<raypack::app::OptionSpec> kSpec = {
    {"--output", "-o", 1}, {"--res", "", 2},     {"--depth", "", 1},   {"--threads", "", 1},
    {"--spp", "", 1},      {"--seed", "", 1},    {"--exposure", "", 1}, {"--json", "", 0},
    {"--quiet", "-q", 0},  {"--integrator", "", 1}};

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    std::vector<std::string> words(1);
    for (std::size_t i = 0; i < size; ++i) {
        if (data[i] == 0) words.emplace_back();
        else words.back().push_back(char(data[i]));
    }
    std::vector<char*> argv;
    for (std::string& w : words) argv.push_back(w.data());
    raypack::app::Args args(int(argv.size()), argv.data());
    try {
        const raypack::app::ParsedArgs p(args, kSpec, 2);
        (void)p.integer("--res", 1, 1, 65536, 0);
        (void)p.integer("--res", 1, 1, 65536, 1);
        (void)p.integer("--spp", 1, 1, 1 << 16);
        (void)p.number("--exposure", 1, 0, 1e30);
        (void)p.text("--integrator");
    } catch (const raypack::app::UsageError&) {
    }
    return 0;
}
