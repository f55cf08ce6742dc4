#include "measure/colormap.h"

#include <algorithm>
#include <cmath>

namespace raypack {

Vec3f viridis(float t) {
    // matplotlib.colormaps["viridis"](i / 16), i = 0..16, interpolated linearly.
    static constexpr float kTable[17][3] = {
        {0.2670f, 0.0049f, 0.3294f}, {0.2823f, 0.0950f, 0.4173f}, {0.2788f, 0.1755f, 0.4834f},
        {0.2590f, 0.2515f, 0.5247f}, {0.2297f, 0.3224f, 0.5457f}, {0.1994f, 0.3876f, 0.5546f},
        {0.1727f, 0.4488f, 0.5579f}, {0.1490f, 0.5081f, 0.5573f}, {0.1276f, 0.5669f, 0.5506f},
        {0.1206f, 0.6258f, 0.5335f}, {0.1579f, 0.6838f, 0.5017f}, {0.2461f, 0.7389f, 0.4520f},
        {0.3692f, 0.7889f, 0.3829f}, {0.5160f, 0.8312f, 0.2943f}, {0.6785f, 0.8637f, 0.1895f},
        {0.8456f, 0.8873f, 0.0997f}, {0.9932f, 0.9062f, 0.1439f},
    };
    const float x = std::clamp(std::isnan(t) ? 0.0f : t, 0.0f, 1.0f) * 16.0f;
    const int i = std::min(15, int(x));
    const float f = x - float(i);
    const float* a = kTable[i];
    const float* b = kTable[i + 1];
    return {a[0] + f * (b[0] - a[0]), a[1] + f * (b[1] - a[1]), a[2] + f * (b[2] - a[2])};
}

}  // namespace raypack
