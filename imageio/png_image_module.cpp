// libraypack_png.so: PNG writing through libpng alone. Loading it takes a
// fraction of a millisecond where the OpenImageIO module takes about 250 ms
// (its ~260 libraries), and PNG is what `render` writes by default. Reading,
// and every other format, stay with libraypack_image.so.
#include <png.h>

#include <cmath>
#include <cstdio>
#include <cstring>
#include <string>
#include <vector>

#include "render/image_module.h"

namespace {

int fail(const std::string& message, char* error, std::size_t error_size) {
    if (error_size > 0) std::snprintf(error, error_size, "%s", message.c_str());
    return 1;
}

bool is_png(const char* path) {
    const std::size_t n = std::strlen(path);
    return n >= 4 && strcasecmp(path + n - 4, ".png") == 0;
}

int check_writer(const char* path, char* error, std::size_t error_size) {
    return is_png(path) ? 0 : fail("the PNG module writes only .png files", error, error_size);
}

/// [0, 1] to 0..255 as OpenImageIO converts float to UINT8: round half away
/// from zero of v * 255, so that a PNG is the same whichever module wrote it
/// (tests/test_image_module.cpp compares them around every rounding threshold).
unsigned char to_byte(float v) { return static_cast<unsigned char>(std::round(std::fmin(std::fmax(v, 0.0f), 1.0f) * 255.0f)); }

int write_rgb(const char* path, int width, int height, const float* rgb, char* error, std::size_t error_size) {
    std::vector<unsigned char> bytes(std::size_t(width) * std::size_t(height) * 3);
    for (std::size_t i = 0; i < bytes.size(); ++i) bytes[i] = to_byte(rgb[i]);
    png_image image;
    std::memset(&image, 0, sizeof image);
    image.version = PNG_IMAGE_VERSION;
    image.width = png_uint_32(width);
    image.height = png_uint_32(height);
    image.format = PNG_FORMAT_RGB;
    if (!png_image_write_to_file(&image, path, 0, bytes.data(), 0, nullptr))
        return fail(std::string("libpng: ") + image.message, error, error_size);
    return 0;
}

}  // namespace

extern "C" __attribute__((visibility("default"))) const RaypackImageModule raypack_image_module = {
    kRaypackImageModuleVersion, check_writer, write_rgb, nullptr};
