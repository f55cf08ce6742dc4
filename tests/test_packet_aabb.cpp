// Slab tests at every width: K rays against one box and one ray against K
// boxes give, lane for lane, the width-1 answer bit for bit (the same
// operations run in every lane), for the plain and the robust variant, on
// 2^20 seeded random rays and on adversarial ones.
#include <gtest/gtest.h>

#include <bit>
#include <random>
#include <type_traits>
#include <vector>

#include "kernels/aabb.h"

namespace raypack {
namespace {

struct Case {
    Vec3f org, dir;
    float tnear, tfar;
    Vec3f lo, hi;
};

/// Random rays and boxes, then rays built to sit exactly on the numerical
/// edges: origins on slab planes and box edges, +-0 and tiny direction
/// components, rays aimed exactly at box corners, tnear = tfar.
std::vector<Case> make_cases() {
    std::vector<Case> cases;
    std::mt19937 rng(2024);
    std::uniform_real_distribution<float> u(-2.0f, 2.0f), e(0.01f, 1.5f);
    auto box = [&] {
        const Vec3f c{u(rng), u(rng), u(rng)}, h{e(rng), e(rng), e(rng)};
        return std::pair{c - h, c + h};
    };
    for (int i = 0; i < (1 << 20); ++i) {
        // Aimed near the box, so that about half of the rays meet it.
        const auto [lo, hi] = box();
        const Vec3f org{u(rng) * 2, u(rng) * 2, u(rng) * 2};
        const Vec3f target = (lo + hi) * 0.5f + (hi - lo) * (0.5f * u(rng)) * 1.0f;
        cases.push_back({org, target - org + Vec3f{u(rng), u(rng), u(rng)} * 0.2f, 0.0f,
                         i % 3 ? std::numeric_limits<float>::infinity() : e(rng) * 3, lo, hi});
    }
    const float zeros[] = {0.0f, -0.0f, 1e-30f, -1e-30f};
    for (int i = 0; i < 40000; ++i) {
        const auto [lo, hi] = box();
        Case c{{u(rng) * 3, u(rng) * 3, u(rng) * 3}, {u(rng), u(rng), u(rng)}, 0.0f,
               std::numeric_limits<float>::infinity(), lo, hi};
        const int axis = i % 3, other = (i / 3) % 3;
        switch (i % 5) {
            case 0:  // origin on a slab plane, direction parallel to it
                c.org[axis] = (i & 8) ? lo[axis] : hi[axis];
                c.dir[axis] = zeros[(i / 15) % 4];
                break;
            case 1:  // on a box edge, parallel to two slabs
                c.org[axis] = lo[axis];
                c.org[(axis + 1) % 3] = hi[(axis + 1) % 3];
                c.dir[axis] = zeros[(i / 15) % 4];
                c.dir[(axis + 1) % 3] = zeros[(i / 7) % 4];
                break;
            case 2: {  // aimed exactly at a corner
                const Vec3f corner{(i & 1) ? hi.x : lo.x, (i & 2) ? hi.y : lo.y, (i & 4) ? hi.z : lo.z};
                c.dir = corner - c.org;
                break;
            }
            case 3:  // axis-parallel
                c.dir = {zeros[(i / 5) % 4], zeros[(i / 20) % 4], zeros[(i / 80) % 4]};
                c.dir[other] = (i & 1) ? 1.0f : -1.0f;
                break;
            default:  // empty interval exactly at the entry
                c.tnear = c.tfar = std::fabs(u(rng));
                break;
        }
        cases.push_back(c);
    }
    return cases;
}

const std::vector<Case>& cases() {
    static const std::vector<Case> all = make_cases();
    return all;
}

template <SlabMethod M>
bool scalar_slab(const Case& c, float& entry) {
    const Vec3f rd = reciprocal(c.dir);
    const SlabRay<float> ray = make_slab_ray(c.org, rd, c.tnear, c.tfar);
    return intersect_box<M, float>(true, ray, c.lo, c.hi, entry);
}

template <class F>
F gather(const std::vector<Case>& cs, std::size_t first, auto field) {
    alignas(64) float v[lanes_of<F>];
    for (int l = 0; l < lanes_of<F>; ++l) v[l] = field(cs[first + std::size_t(l)]);
    return load_lanes<F>(v);
}

template <class F>
Vec3<F> gather3(const std::vector<Case>& cs, std::size_t first, auto field) {
    return {gather<F>(cs, first, [&](const Case& c) { return field(c).x; }),
            gather<F>(cs, first, [&](const Case& c) { return field(c).y; }),
            gather<F>(cs, first, [&](const Case& c) { return field(c).z; })};
}

template <class K>
class PacketAabb : public ::testing::Test {};
using Widths = ::testing::Types<std::integral_constant<int, 1>
#if defined(__SSE4_2__)
                                , std::integral_constant<int, 4>
#endif
#if defined(__AVX2__)
                                , std::integral_constant<int, 8>
#endif
#if defined(__AVX512BW__)
                                , std::integral_constant<int, 16>
#endif
                                >;
TYPED_TEST_SUITE(PacketAabb, Widths);

template <SlabMethod M, int K>
void check_packets_equal_scalar() {
    using F = vfloat<K>;
    const auto& cs = cases();
    std::size_t differ = 0, hits = 0;
    for (std::size_t first = 0; first + K <= cs.size(); first += K) {
        // K rays against one box: the box of the first case, broadcast.
        const Case& b = cs[first];
        const Vec3<F> org = gather3<F>(cs, first, [](const Case& c) { return c.org; });
        const Vec3<F> dir = gather3<F>(cs, first, [](const Case& c) { return c.dir; });
        const SlabRay<F> ray = make_slab_ray(org, reciprocal(dir), gather<F>(cs, first, [](const Case& c) { return c.tnear; }),
                                             gather<F>(cs, first, [](const Case& c) { return c.tfar; }));
        F entry;
        const std::uint32_t bits = mask_bits(intersect_box<M, F>(mask_of<F>(true), ray, Vec3<F>{F(b.lo.x), F(b.lo.y), F(b.lo.z)},
                                                                 Vec3<F>{F(b.hi.x), F(b.hi.y), F(b.hi.z)}, entry));
        for (int l = 0; l < K; ++l) {
            Case c = cs[first + std::size_t(l)];
            c.lo = b.lo;
            c.hi = b.hi;
            float want_entry;
            const bool want = scalar_slab<M>(c, want_entry);
            const bool got = (bits >> l) & 1u;
            hits += want;
            if (want != got || (want && std::bit_cast<std::uint32_t>(want_entry) !=
                                            std::bit_cast<std::uint32_t>(lane(entry, l))))
                ++differ;
        }
        // One ray (the first) against K boxes in SoA.
        const Vec3<F> lo = gather3<F>(cs, first, [](const Case& c) { return c.lo; });
        const Vec3<F> hi = gather3<F>(cs, first, [](const Case& c) { return c.hi; });
        const Vec3f rd = reciprocal(b.dir);
        const SlabRay<F> one{{F(b.org.x), F(b.org.y), F(b.org.z)},
                             {F(rd.x), F(rd.y), F(rd.z)},
                             {F(b.org.x * rd.x), F(b.org.y * rd.y), F(b.org.z * rd.z)},
                             F(b.tnear),
                             F(b.tfar)};
        const std::uint32_t bits2 = mask_bits(intersect_box<M, F>(mask_of<F>(true), one, lo, hi, entry));
        for (int l = 0; l < K; ++l) {
            Case c = b;
            c.lo = cs[first + std::size_t(l)].lo;
            c.hi = cs[first + std::size_t(l)].hi;
            float want_entry;
            const bool want = scalar_slab<M>(c, want_entry);
            const bool got = (bits2 >> l) & 1u;
            if (want != got || (want && std::bit_cast<std::uint32_t>(want_entry) !=
                                            std::bit_cast<std::uint32_t>(lane(entry, l))))
                ++differ;
        }
    }
    EXPECT_EQ(differ, 0u);
    EXPECT_GT(hits, cs.size() / 20);  // the cases exercise both answers
    EXPECT_LT(hits, cs.size() - cs.size() / 20);
}

TYPED_TEST(PacketAabb, PlainLanesEqualWidthOne) { check_packets_equal_scalar<SlabMethod::Plain, TypeParam::value>(); }
TYPED_TEST(PacketAabb, RobustLanesEqualWidthOne) { check_packets_equal_scalar<SlabMethod::Robust, TypeParam::value>(); }

/// Against exact geometry in double: robust never misses a box the ray
/// touches (corners, planes, parallel rays inside slabs); plain may, and only
/// in those boundary cases. Every robust miss is checked against the exact
/// answer.
TEST(PacketAabbExact, RobustNeverMissesWhatTheExactRayTouches) {
    std::size_t robust_misses = 0, plain_misses = 0, touching = 0;
    for (const Case& c : cases()) {
        // Exact slab test in double with explicit parallel handling.
        double t0 = c.tnear, t1 = c.tfar;
        bool inside = true;
        for (int a = 0; a < 3; ++a) {
            if (c.dir[a] == 0.0f) {
                inside &= c.org[a] >= c.lo[a] && c.org[a] <= c.hi[a];
                continue;
            }
            double ta = (double(c.lo[a]) - c.org[a]) / c.dir[a], tb = (double(c.hi[a]) - c.org[a]) / c.dir[a];
            if (ta > tb) std::swap(ta, tb);
            t0 = std::max(t0, ta);
            t1 = std::min(t1, tb);
        }
        if (!(inside && t0 <= t1)) continue;
        ++touching;
        float entry;
        robust_misses += !scalar_slab<SlabMethod::Robust>(c, entry);
        plain_misses += !scalar_slab<SlabMethod::Plain>(c, entry);
    }
    EXPECT_GT(touching, 100000u);
    EXPECT_EQ(robust_misses, 0u);
    std::printf("boxes touched by the exact ray: %zu; plain misses %zu of them, robust %zu\n", touching, plain_misses,
                robust_misses);
}

}  // namespace
}  // namespace raypack
