// raypack: the command line. Each subcommand lives in its own file.
#include <cstdio>
#include <cstring>
#include <exception>
#include <string>

#include "app/commands.h"
#include "app/heap_pages.h"
#include "render/image.h"
#include "scene/load.h"

namespace {

void print_usage(std::FILE* out) {
    std::fputs(
        "usage: raypack COMMAND [options]\n"
        "\n"
        "commands:\n"
        "  render SCENE [-o out.png] [--res W H] [--depth D] [--threads T]\n"
        "  trace  SCENE --rays FILE.rays [-o FILE.hits] [--threads T] [--repeat R] [--stream] [--json]\n"
        "  info   SCENE\n"
        "  gen    NAME --size S -o FILE.nff\n"
        "  rays   SCENE --kind camera|shadow|diffuse [--res W H] -o FILE.rays\n"
        "  bench  [SCENE...] [--accel LIST] [--packet LIST] [--rays KINDS] [--quick] [--json F] [--csv F]\n"
        "\n"
        "SCENE is an .nff or .obj file, or gen:NAME:SIZE for a generated SPD scene.\n"
        "Run 'raypack COMMAND --help' for a command's options.\n",
        out);
}

}  // namespace

int main(int argc, char** argv) {
    raypack::app::reserve_heap_in_large_pages();
    // Commands start loading their image module in the background
    // (render/image.h): no way out of main leaves while it still loads.
    struct WaitForImageModules {
        ~WaitForImageModules() { raypack::wait_for_image_modules(); }
    } wait_for_image_modules_on_exit;
    // NFF's `hf FILE`: heights from an image's first channel, through OpenImageIO.
    raypack::set_height_image_reader([](const std::string& path, std::uint32_t& w, std::uint32_t& h) {
        const raypack::Image image = raypack::read_image(path);
        w = std::uint32_t(image.width);
        h = std::uint32_t(image.height);
        std::vector<float> first(std::size_t(w) * h);
        for (std::size_t p = 0; p < first.size(); ++p) first[p] = image.rgb[p * 3];
        return first;
    });
    if (argc < 2) {
        print_usage(stderr);
        return 2;
    }
    const std::string command = argv[1];
    if (command == "-h" || command == "--help" || command == "help") {
        print_usage(stdout);
        return 0;
    }
    const raypack::app::Args args(argc - 2, argv + 2);
    try {
        if (command == "render") return raypack::app::run_render(args);
        if (command == "trace") return raypack::app::run_trace(args);
        if (command == "info") return raypack::app::run_info(args);
        if (command == "gen") return raypack::app::run_gen(args);
        if (command == "rays") return raypack::app::run_rays(args);
        if (command == "bench") return raypack::app::run_bench(args);
    } catch (const raypack::app::UsageError& e) {
        std::fprintf(stderr, "raypack %s: %s\n", command.c_str(), e.what());
        return 2;
    } catch (const std::exception& e) {
        std::fprintf(stderr, "raypack %s: error: %s\n", command.c_str(), e.what());
        return 1;
    }
    std::fprintf(stderr, "raypack: unknown command '%s'\n\n", command.c_str());
    print_usage(stderr);
    return 2;
}
