#include "render/image.h"

#include <OpenImageIO/imageio.h>

#include <algorithm>
#include <stdexcept>

#include "scene/atomic_file.h"

namespace raypack {

void write_image(const std::string& path, const Image& image) {
    // Fail before touching the file system when the format is unknown.
    if (!OIIO::ImageOutput::create(path))
        throw std::runtime_error(path + ": no image writer for this file extension (" + OIIO::geterror() + ")");
    write_atomically(path, [&](const std::string& tmp) {
        auto out = OIIO::ImageOutput::create(tmp);
        if (!out) throw std::runtime_error(path + ": " + OIIO::geterror());
        const bool is_exr = std::string(out->format_name()) == "openexr";
        const OIIO::TypeDesc type = is_exr ? OIIO::TypeDesc::HALF : OIIO::TypeDesc::UINT8;
        OIIO::ImageSpec spec(image.width, image.height, 3, type);
        if (!out->open(tmp, spec)) throw std::runtime_error(path + ": " + out->geterror());
        std::vector<float> pixels = image.rgb;
        if (!is_exr)
            for (float& v : pixels) v = std::clamp(v, 0.0f, 1.0f);
        if (!out->write_image(OIIO::TypeDesc::FLOAT, pixels.data()) || !out->close())
            throw std::runtime_error(path + ": " + out->geterror());
    });
}

Image read_image(const std::string& path) {
    auto in = OIIO::ImageInput::open(path);
    if (!in) throw std::runtime_error(path + ": cannot read image (" + OIIO::geterror() + ")");
    const OIIO::ImageSpec& spec = in->spec();
    Image image(spec.width, spec.height);
    std::vector<float> all(std::size_t(spec.width) * std::size_t(spec.height) * std::size_t(spec.nchannels));
    if (!in->read_image(0, 0, 0, spec.nchannels, OIIO::TypeDesc::FLOAT, all.data()))
        throw std::runtime_error(path + ": " + in->geterror());
    for (std::size_t p = 0; p < std::size_t(spec.width) * std::size_t(spec.height); ++p)
        for (int c = 0; c < 3; ++c)
            image.rgb[p * 3 + std::size_t(c)] = all[p * std::size_t(spec.nchannels) + std::size_t(std::min(c, spec.nchannels - 1))];
    return image;
}

}  // namespace raypack
