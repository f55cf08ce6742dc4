#include "render/image.h"

#include <dlfcn.h>
#include <strings.h>
#include <unistd.h>

#include <array>
#include <cstdlib>
#include <filesystem>
#include <future>
#include <mutex>
#include <stdexcept>

#include "render/image_module.h"
#include "scene/atomic_file.h"

namespace raypack {
namespace {

/// A loaded module, or why it could not be loaded.
struct LoadedModule {
    const RaypackImageModule* module = nullptr;
    std::string error;
};

/// One image module: its file, the variable that overrides where it is, and
/// its load, started once.
struct ModuleSlot {
    const char* file;
    const char* env;
    std::once_flag started;
    std::shared_future<LoadedModule> loaded;
};

ModuleSlot g_oiio{"libraypack_image.so", "RAYPACK_IMAGE_MODULE", {}, {}};
ModuleSlot g_png{"libraypack_png.so", "RAYPACK_PNG_MODULE", {}, {}};

/// PNG goes to the small libpng module; everything else to OpenImageIO.
ModuleSlot& writer_slot(const std::string& path) {
    const std::size_t n = path.size();
    return n >= 4 && strcasecmp(path.c_str() + n - 4, ".png") == 0 ? g_png : g_oiio;
}

/// The directory of the running executable, or "" if /proc does not say.
std::string executable_dir() {
    std::array<char, 4096> buf{};
    const ssize_t n = readlink("/proc/self/exe", buf.data(), buf.size() - 1);
    if (n <= 0) return {};
    return std::filesystem::path(std::string(buf.data(), std::size_t(n))).parent_path().string();
}

/// `where` says how `path` was chosen, for the error message.
LoadedModule open_module(const std::string& path, const std::string& where) {
    // RTLD_NOW: an unresolved symbol is an error here, not a crash later.
    void* handle = dlopen(path.c_str(), RTLD_NOW | RTLD_LOCAL);
    if (!handle) return {nullptr, "cannot load the image module " + path + " (" + where + "): " + dlerror()};
    const auto* module = static_cast<const RaypackImageModule*>(dlsym(handle, kRaypackImageModuleSymbol));
    if (!module) return {nullptr, "image module " + path + ": " + dlerror()};
    if (module->version != kRaypackImageModuleVersion)
        return {nullptr, "image module " + path + ": interface version " + std::to_string(module->version) +
                             ", this raypack expects " + std::to_string(kRaypackImageModuleVersion)};
    return {module, {}};
}

/// The search rule: the module's variable (RAYPACK_IMAGE_MODULE,
/// RAYPACK_PNG_MODULE) if set, a path to the file; else the file next to the
/// executable; else the dynamic loader's search (the executable's RUNPATH,
/// which the build sets to the build directory, then LD_LIBRARY_PATH and the
/// system directories).
LoadedModule load_module(const ModuleSlot& slot) {
    if (const char* env = std::getenv(slot.env); env && *env) return open_module(env, std::string("from ") + slot.env);
    const std::string dir = executable_dir();
    if (!dir.empty()) {
        const std::string beside = dir + "/" + slot.file;
        std::error_code ec;
        if (std::filesystem::exists(beside, ec)) return open_module(beside, "next to the executable");
    }
    return open_module(slot.file, "not next to the executable " + (dir.empty() ? "?" : dir) +
                                      "; searched the RUNPATH, LD_LIBRARY_PATH and system directories");
}

void start_loading(ModuleSlot& slot) {
    std::call_once(slot.started,
                   [&slot] { slot.loaded = std::async(std::launch::async, load_module, std::cref(slot)).share(); });
}

/// The module, loading it (or waiting for the background load) on first use.
const RaypackImageModule& module_of(ModuleSlot& slot) {
    start_loading(slot);
    const LoadedModule& loaded = slot.loaded.get();
    if (!loaded.module) throw std::runtime_error(loaded.error);
    return *loaded.module;
}

}  // namespace

void start_loading_image_module(const std::string& path_to_write) { start_loading(writer_slot(path_to_write)); }

void wait_for_image_modules() {
    for (ModuleSlot* slot : {&g_oiio, &g_png})
        if (slot->loaded.valid()) slot->loaded.wait();
}

void write_image(const std::string& path, const Image& image) {
    const RaypackImageModule& module = module_of(writer_slot(path));
    std::array<char, 1024> error{};
    // Fail before touching the file system when the format is unknown.
    if (module.check_writer(path.c_str(), error.data(), error.size()) != 0)
        throw std::runtime_error(path + ": " + error.data());
    write_atomically(path, [&](const std::string& tmp) {
        if (module.write_rgb(tmp.c_str(), image.width, image.height, image.rgb.data(), error.data(), error.size()) != 0)
            throw std::runtime_error(path + ": " + error.data());
    });
}

Image read_image(const std::string& path) {
    const RaypackImageModule& module = module_of(g_oiio);
    std::array<char, 1024> error{};
    Image image;
    const auto allocate = [](void* context, int width, int height) {
        Image& target = *static_cast<Image*>(context);
        target = Image(width, height);
        return target.rgb.data();
    };
    if (module.read_rgb(path.c_str(), &image, allocate, error.data(), error.size()) != 0)
        throw std::runtime_error(path + ": " + error.data());
    return image;
}

}  // namespace raypack
