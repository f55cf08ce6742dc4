#pragma once
// The interface between raypack and its image modules: libraypack_image.so
// (imageio/oiio_image_module.cpp) reads and writes images through
// OpenImageIO; libraypack_png.so (imageio/png_image_module.cpp) writes PNG
// through libpng alone. OpenImageIO pulls in about 260 shared libraries whose symbols
// are bound at load; keeping them in a module loaded with dlopen when an image
// is first needed keeps them out of every command that writes no image.
// Plain C types only, so that the loader and the module agree without sharing
// any C++ object layout.
#include <cstddef>

extern "C" {

/// Raised when the functions below change, so that an old module is refused.
inline constexpr int kRaypackImageModuleVersion = 1;

/// What the module exports under the name in kRaypackImageModuleSymbol. Every
/// function returns 0 on success; on failure it returns non-zero and writes a
/// message (without the file name) into error[0, error_size).
struct RaypackImageModule {
    int version;
    /// Whether some writer takes the format `path`'s extension names.
    int (*check_writer)(const char* path, char* error, std::size_t error_size);
    /// Writes width x height linear RGB floats (rows from the top) to `path`,
    /// in the format its extension names: half floats for OpenEXR, otherwise
    /// 8 bits clamped to [0, 1].
    int (*write_rgb)(const char* path, int width, int height, const float* rgb, char* error, std::size_t error_size);
    /// Reads `path` as linear RGB floats into the buffer that
    /// allocate(context, width, height) returns (width * height * 3 floats).
    /// Null in a module that only writes.
    int (*read_rgb)(const char* path, void* context, float* (*allocate)(void* context, int width, int height),
                    char* error, std::size_t error_size);
};

}  // extern "C"

namespace raypack {
/// The symbol the loader reads from a module.
inline constexpr const char* kRaypackImageModuleSymbol = "raypack_image_module";
}  // namespace raypack
