// raypack bench's check before timing must catch a structure that answers
// wrongly, and name the case and the ray.
#include <gtest/gtest.h>

#include "app/bench_measure.h"
#include "scene/load.h"

namespace raypack::app {
namespace {

/// BVH2 answers with one ray's hit dropped: what a traversal bug looks like.
class DropsOneHit final : public Accel {
public:
    DropsOneHit(const Scene& scene, const Rayf& victim)
        : inner_(build_accel(scene, AccelConfig{})), victim_org_(victim.org), victim_dir_(victim.dir) {}
    void intersect(std::span<const Rayf> rays, std::span<Hitf> hits) const override {
        inner_->intersect(rays, hits);
        for (std::size_t i = 0; i < rays.size(); ++i)
            if (rays[i].org.x == victim_org_.x && rays[i].dir.x == victim_dir_.x && rays[i].dir.y == victim_dir_.y)
                hits[i] = Hitf{};
    }
    void occluded(std::span<const Rayf> rays, std::span<std::uint8_t> occluded) const override {
        inner_->occluded(rays, occluded);
    }
    const AccelStats& stats() const override { return inner_->stats(); }

private:
    std::unique_ptr<Accel> inner_;
    Vec3f victim_org_, victim_dir_;
};

TEST(BenchValidation, AgreeingStructurePasses) {
    const Scene scene = load_scene("gen:balls:2");
    const BenchRays set = make_bench_rays(scene, "diffuse", 64, 64);
    const OracleSample sample = oracle_sample(scene, set, 512);
    ASSERT_EQ(sample.rays.size(), 512u);
    for (const char* kind : {"bvh2", "grid", "kdtree"})
        EXPECT_NO_THROW(validate_against_oracle(*build_accel(scene, accel_config(kind)), 1, set, sample, kind));
}

TEST(BenchValidation, DroppedHitIsAnErrorNamingCaseAndRay) {
    const Scene scene = load_scene("gen:balls:2");
    const BenchRays set = make_bench_rays(scene, "camera", 64, 64);
    const OracleSample sample = oracle_sample(scene, set, 512);
    // A sampled ray that hits something.
    std::size_t k = 0;
    while (k < sample.rays.size() && !sample.expected[k].found()) ++k;
    ASSERT_LT(k, sample.rays.size());
    const DropsOneHit broken(scene, sample.rays[k]);
    try {
        validate_against_oracle(broken, 1, set, sample, "balls broken K=1 camera");
        FAIL() << "a dropped hit must fail validation";
    } catch (const std::runtime_error& e) {
        const std::string what = e.what();
        EXPECT_NE(what.find("balls broken K=1 camera"), std::string::npos) << what;
        EXPECT_NE(what.find("ray " + std::to_string(sample.index[k]) + " "), std::string::npos) << what;
        EXPECT_NE(what.find("got miss"), std::string::npos) << what;
    }
}

}  // namespace
}  // namespace raypack::app
