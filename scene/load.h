#pragma once
// Scene loading: NFF, OBJ and generated SPD scenes, by one entry point.
#include <cstdint>
#include <functional>
#include <iosfwd>
#include <stdexcept>
#include <string>
#include <vector>

#include "scene/scene.h"

namespace raypack {

/// Bad input: the message names the file, the line (0 when unknown) and the problem,
/// and what() reads "FILE:LINE: PROBLEM".
class SceneError : public std::runtime_error {
public:
    SceneError(const std::string& file, int line, const std::string& problem);
    const std::string& file() const { return file_; }
    int line() const { return line_; }
    const std::string& problem() const { return problem_; }

private:
    std::string file_;
    int line_;
    std::string problem_;
};

/// Reads an image's first channel as floats, row-major from the top row, for
/// NFF's `hf FILE`: the scene layer reads no images itself, so the program
/// installs one (raypack's reads through OpenImageIO, render/image.h).
using HeightImageReader =
    std::function<std::vector<float>(const std::string& path, std::uint32_t& width, std::uint32_t& height)>;
void set_height_image_reader(HeightImageReader reader);
const HeightImageReader& height_image_reader();

/// SPEC is a path ending in .nff or .obj, or gen:NAME:SIZE (see scene/spd/spd.h).
Scene load_scene(const std::string& spec);

/// NFF as a stream of whitespace-separated tokens; `name` is used in errors.
Scene load_nff(std::istream& in, const std::string& name);
Scene load_nff_file(const std::string& path);

/// Wavefront OBJ through tinyobjloader. Adds a camera and a light that frame
/// the mesh, since OBJ has neither.
Scene load_obj_file(const std::string& path);

}  // namespace raypack
