#include "measure/digit_font.h"

namespace raypack {
namespace {

// Rows top to bottom, 3 bits each, the high bit on the left.
constexpr unsigned char kDigits[10][5] = {
    {7, 5, 5, 5, 7}, {2, 6, 2, 2, 7}, {7, 1, 7, 4, 7}, {7, 1, 7, 1, 7}, {5, 5, 7, 1, 1},
    {7, 4, 7, 1, 7}, {7, 4, 7, 5, 7}, {7, 1, 1, 1, 1}, {7, 5, 7, 5, 7}, {7, 5, 7, 1, 7},
};
constexpr int kAdvance = 4;  // 3 columns and a blank one

}  // namespace

int text_width(const std::string& text, int scale) { return text.empty() ? 0 : (int(text.size()) * kAdvance - 1) * scale; }

void draw_text(Image& image, int x, int y, const std::string& text, int scale, const Vec3f& colour) {
    for (std::size_t c = 0; c < text.size(); ++c) {
        if (text[c] < '0' || text[c] > '9') continue;
        const unsigned char* glyph = kDigits[text[c] - '0'];
        for (int row = 0; row < 5 * scale; ++row)
            for (int col = 0; col < 3 * scale; ++col) {
                if (!(glyph[row / scale] & (4 >> (col / scale)))) continue;
                const int px = x + (int(c) * kAdvance) * scale + col, py = y + row;
                if (px >= 0 && py >= 0 && px < image.width && py < image.height) image.set(px, py, colour);
            }
    }
}

}  // namespace raypack
