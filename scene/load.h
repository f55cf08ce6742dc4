#pragma once
// Scene loading: NFF, OBJ and generated SPD scenes, by one entry point.
#include <iosfwd>
#include <stdexcept>
#include <string>

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

/// SPEC is a path ending in .nff or .obj, or gen:NAME:SIZE (see scene/spd/spd.h).
Scene load_scene(const std::string& spec);

/// NFF as a stream of whitespace-separated tokens; `name` is used in errors.
Scene load_nff(std::istream& in, const std::string& name);
Scene load_nff_file(const std::string& path);

/// Wavefront OBJ through tinyobjloader. Adds a camera and a light that frame
/// the mesh, since OBJ has neither.
Scene load_obj_file(const std::string& path);

}  // namespace raypack
