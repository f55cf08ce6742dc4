// libraypack_image.so: image reading and writing through OpenImageIO, loaded
// by render/image.cpp with dlopen when an image is first read or written
// (render/image_module.h says why).
#include <OpenImageIO/imageio.h>

#include <algorithm>
#include <cstdio>
#include <string>
#include <vector>

#include "render/image_module.h"

namespace {

int fail(const std::string& message, char* error, std::size_t error_size) {
    if (error_size > 0) std::snprintf(error, error_size, "%s", message.c_str());
    return 1;
}

int check_writer(const char* path, char* error, std::size_t error_size) {
    if (OIIO::ImageOutput::create(path)) return 0;
    return fail("no image writer for this file extension (" + OIIO::geterror() + ")", error, error_size);
}

int write_rgb(const char* path, int width, int height, const float* rgb, char* error, std::size_t error_size) {
    auto out = OIIO::ImageOutput::create(path);
    if (!out) return fail(OIIO::geterror(), error, error_size);
    const bool is_exr = std::string(out->format_name()) == "openexr";
    // EXR keeps the renderer's floats exactly (full float, not half).
    const OIIO::TypeDesc type = is_exr ? OIIO::TypeDesc::FLOAT : OIIO::TypeDesc::UINT8;
    OIIO::ImageSpec spec(width, height, 3, type);
    // No time stamp: the same render gives the same bytes.
    spec.attribute("DateTime", "");
    if (!out->open(path, spec)) return fail(out->geterror(), error, error_size);
    std::vector<float> pixels(rgb, rgb + std::size_t(width) * std::size_t(height) * 3);
    if (!is_exr)
        for (float& v : pixels) v = std::clamp(v, 0.0f, 1.0f);
    if (!out->write_image(OIIO::TypeDesc::FLOAT, pixels.data()) || !out->close())
        return fail(out->geterror(), error, error_size);
    return 0;
}

int read_rgb(const char* path, void* context, float* (*allocate)(void*, int, int), char* error,
             std::size_t error_size) {
    auto in = OIIO::ImageInput::open(path);
    if (!in) return fail("cannot read image (" + OIIO::geterror() + ")", error, error_size);
    const OIIO::ImageSpec& spec = in->spec();
    std::vector<float> all(std::size_t(spec.width) * std::size_t(spec.height) * std::size_t(spec.nchannels));
    if (!in->read_image(0, 0, 0, spec.nchannels, OIIO::TypeDesc::FLOAT, all.data()))
        return fail(in->geterror(), error, error_size);
    float* rgb = allocate(context, spec.width, spec.height);
    for (std::size_t p = 0; p < std::size_t(spec.width) * std::size_t(spec.height); ++p)
        for (int c = 0; c < 3; ++c)
            rgb[p * 3 + std::size_t(c)] = all[p * std::size_t(spec.nchannels) + std::size_t(std::min(c, spec.nchannels - 1))];
    return 0;
}

}  // namespace

extern "C" __attribute__((visibility("default"))) const RaypackImageModule raypack_image_module = {
    kRaypackImageModuleVersion, check_writer, write_rgb, read_rgb};
