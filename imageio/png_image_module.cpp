// libraypack_png.so: PNG writing through libpng alone. Loading it takes a
// fraction of a millisecond where the OpenImageIO module takes about 250 ms
// (its ~260 libraries), and PNG is what `render` writes by default. Reading,
// and every other format, stay with libraypack_image.so.
#include <png.h>

#include <cerrno>
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
unsigned char to_byte(float v) {
    // Clamped as fmin(fmax(v, 0), 1), NaN to 0, by comparisons: gcc calls
    // libm's fminf and fmaxf otherwise (2% of a tetra render's process).
    const float y = (v > 0.0f ? (v < 1.0f ? v : 1.0f) : 0.0f) * 255.0f;
    // std::round(y) without its libm call (1.5% of a gears render): for y in
    // [0, 255], y - trunc(y) is exact, so the comparison decides the half.
    const int whole = int(y);
    return static_cast<unsigned char>(whole + (y - float(whole) >= 0.5f ? 1 : 0));
}

/// libpng reports errors by longjmp; the message is kept for the caller.
void on_png_error(png_structp png, png_const_charp message) {
    std::snprintf(static_cast<char*>(png_get_error_ptr(png)), 256, "libpng: %s", message);
    png_longjmp(png, 1);
}

/// Writes 8-bit RGB rows. zlib level 1 with the Sub filter: on the seven SPD
/// renders (512 x 512) it wrote 2-4x faster than libpng's defaults (which
/// OpenImageIO used) for files 5-33% larger (docs/build.md).
bool write_png(std::FILE* file, int width, int height, const unsigned char* bytes, char* message) {
    png_structp png = png_create_write_struct(PNG_LIBPNG_VER_STRING, message, on_png_error, nullptr);
    if (!png) return false;
    png_infop info = png_create_info_struct(png);
    if (!info || setjmp(png_jmpbuf(png))) {
        png_destroy_write_struct(&png, &info);
        return false;
    }
    png_init_io(png, file);
    png_set_IHDR(png, info, png_uint_32(width), png_uint_32(height), 8, PNG_COLOR_TYPE_RGB, PNG_INTERLACE_NONE,
                 PNG_COMPRESSION_TYPE_DEFAULT, PNG_FILTER_TYPE_DEFAULT);
    png_set_compression_level(png, 1);
    png_set_filter(png, PNG_FILTER_TYPE_BASE, PNG_FILTER_SUB);
    png_write_info(png, info);
    for (int y = 0; y < height; ++y) png_write_row(png, bytes + std::size_t(y) * std::size_t(width) * 3);
    png_write_end(png, nullptr);
    png_destroy_write_struct(&png, &info);
    return true;
}

int write_rgb(const char* path, int width, int height, const float* rgb, char* error, std::size_t error_size) {
    std::vector<unsigned char> bytes(std::size_t(width) * std::size_t(height) * 3);
    for (std::size_t i = 0; i < bytes.size(); ++i) bytes[i] = to_byte(rgb[i]);
    std::FILE* file = std::fopen(path, "wb");
    if (!file) return fail(std::string("cannot open for writing: ") + std::strerror(errno), error, error_size);
    char message[256] = "libpng: unknown error";
    const bool written = write_png(file, width, height, bytes.data(), message);
    const bool closed = std::fclose(file) == 0;
    if (!written) return fail(message, error, error_size);
    if (!closed) return fail(std::string("cannot write: ") + std::strerror(errno), error, error_size);
    return 0;
}

}  // namespace

extern "C" __attribute__((visibility("default"))) const RaypackImageModule raypack_image_module = {
    kRaypackImageModuleVersion, check_writer, write_rgb, nullptr};
