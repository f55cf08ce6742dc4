#pragma once
// A 3x5 pixel font for the digits, enough to label a colour scale.
#include <string>

#include "render/image.h"

namespace raypack {

/// Width in pixels of `text` drawn at `scale` (digits only; others are blanks).
int text_width(const std::string& text, int scale);
/// Draws `text` with its top-left corner at (x, y), each font pixel a
/// scale x scale square; pixels outside the image are skipped.
void draw_text(Image& image, int x, int y, const std::string& text, int scale, const Vec3f& colour);

}  // namespace raypack
