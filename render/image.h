#pragma once
// A linear RGB float image, and its reading and writing through the image
// module (OpenImageIO, loaded when first needed: render/image_module.h).
#include <string>
#include <vector>

#include "kernels/vec3.h"

namespace raypack {

struct Image {
    int width = 0, height = 0;
    std::vector<float> rgb;  ///< row-major from the top row, 3 floats per pixel

    Image() = default;
    Image(int w, int h) : width(w), height(h), rgb(std::size_t(w) * std::size_t(h) * 3, 0.0f) {}
    Vec3f at(int x, int y) const {
        const float* p = &rgb[(std::size_t(y) * std::size_t(width) + std::size_t(x)) * 3];
        return {p[0], p[1], p[2]};
    }
    void set(int x, int y, const Vec3f& c) {
        float* p = &rgb[(std::size_t(y) * std::size_t(width) + std::size_t(x)) * 3];
        p[0] = c.x;
        p[1] = c.y;
        p[2] = c.z;
    }
};

/// Starts loading, in a background thread, the image module that will write
/// `path_to_write` (libpng for .png, OpenImageIO otherwise), so that a command
/// does not wait for it before its work; write_image waits for the load.
/// Calling it again does nothing. A process must not exit while a module is
/// still loading (the exit would run the destructors of the libraries loaded
/// so far while the loader thread still runs their constructors): call
/// wait_for_image_modules before leaving main.
void start_loading_image_module(const std::string& path_to_write);

/// Waits for every module load start_loading_image_module began.
void wait_for_image_modules();

/// Writes the image in the format its extension names (.png through libpng;
/// .exr, .tif, .jpg, .ppm, ... through OpenImageIO), 8-bit formats clamped to
/// [0, 1] and rounded as OpenImageIO rounds. Written to a temporary
/// file and renamed. Throws std::runtime_error naming the file on failure,
/// or naming the module and the loader's reason when it cannot be loaded.
void write_image(const std::string& path, const Image& image);

/// Reads any image OpenImageIO reads (through its module), as linear RGB floats (for tests and tools).
Image read_image(const std::string& path);

}  // namespace raypack
