#pragma once
// What every structure with packet traversals shares around them: the
// widths this build compiles (kernels/simd.h: 4 with SSE4.2, 8 with AVX2,
// 16 with AVX-512BW), the one dispatch from a run-time width to the loop
// compiled for it, and any-hit answers taken from a packet loop that reports
// them as hits.
#include <algorithm>
#include <cstdint>
#include <new>
#include <span>
#include <stdexcept>
#include <string>

#include "kernels/ray.h"
#include "kernels/simd.h"

namespace raypack {

/// Width 1 (single rays) or a packet width this build compiles.
inline bool packet_width_compiled(int width) {
    return width == 1 || (width == 4 && kWidthCompiled<4>) || (width == 8 && kWidthCompiled<8>) ||
           (width == 16 && kWidthCompiled<16>);
}

/// Runs fn.template operator()<K>() for K = width, a compiled packet width;
/// any other width is an std::invalid_argument naming `who`.
template <class Fn>
void with_packet_width(int width, const std::string& who, Fn&& fn) {
    if constexpr (kWidthCompiled<4>)
        if (width == 4) return fn.template operator()<4>();
    if constexpr (kWidthCompiled<8>)
        if (width == 8) return fn.template operator()<8>();
    if constexpr (kWidthCompiled<16>)
        if (width == 16) return fn.template operator()<16>();
    throw std::invalid_argument(who + ": packets of " + std::to_string(width) + " are not compiled in");
}

/// occluded[i] from `trace(rays, hits)`, a packet loop whose any-hit answers
/// come as hits (found() = occluded: accel/packet_driver.h), in slices of
/// 2,048 rays through a buffer on the stack (no allocation per call; 32 KB).
/// A slice holds 8 of trace_in_groups' loads of 16 packets, so that each
/// load's walk can ask for the next load's rays (accel/packet_driver.h).
/// The buffer is left uninitialised: every query writes every answer
/// (AccelOracle.QueriesWriteEveryAnswer), and a default-constructed Hitf[2048]
/// cost 32 KB of stores per call, 6% of a teapot render, whose shadow
/// batches are a few hundred rays.
template <class TraceAnyHit>
void occlusion_in_slices(std::span<const Rayf> rays, std::span<std::uint8_t> occluded, TraceAnyHit&& trace) {
    constexpr std::size_t kSlice = 2048;
    // An array of unsigned char implicitly creates the Hitf objects
    // ([intro.object]); Hitf is an aggregate, hence implicit-lifetime.
    alignas(Hitf) unsigned char storage[kSlice * sizeof(Hitf)];
    Hitf* const buffer = std::launder(reinterpret_cast<Hitf*>(storage));
    for (std::size_t first = 0; first < rays.size(); first += kSlice) {
        const std::size_t n = std::min(kSlice, rays.size() - first);
        trace(rays.subspan(first, n), std::span<Hitf>(buffer, n));
        for (std::size_t i = 0; i < n; ++i) occluded[first + i] = buffer[i].found() ? 1 : 0;
    }
}

}  // namespace raypack
