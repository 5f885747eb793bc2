#include "reflectance/specular_fit.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

#include "reflectance/ward_observations.h"

namespace glint::reflectance {
namespace {

using test_support::observed;

// 25 voxels of one material with spatially varying kd on a bumpy surface, each seen from 20
// directions (16 spread over the hemisphere, 4 near the mirror directions of the lights; those
// within 3 degrees of the horizon are left out).
struct Segment {
  std::vector<std::vector<Observation>> observations;
  std::vector<FitVoxel> voxels;
};

std::vector<render::PointLight> two_lights() {
  std::vector<render::PointLight> lights(2);
  lights[0].position = {0.4, 2.0, 0.3};
  lights[0].intensity = {4.0f, 4.0f, 4.0f};
  lights[1].position = {-1.2, 1.6, -0.4};
  lights[1].intensity = {1.5f, 1.2f, 1.0f};
  return lights;
}

Segment render_segment(Eigen::Vector3f ks, float alpha,
                       const std::vector<render::PointLight>& lights,
                       float clip = std::numeric_limits<float>::infinity()) {
  std::mt19937 random(7);
  std::uniform_real_distribution<float> uniform(-1.0f, 1.0f);
  Segment segment;
  segment.observations.resize(25);
  for (int v = 0; v < 25; ++v) {
    render::WardMaterial m;
    m.kd = Eigen::Vector3f(0.3f, 0.4f, 0.2f) +
           0.2f * Eigen::Vector3f(uniform(random), uniform(random), uniform(random));
    m.ks = ks;
    m.alpha = alpha;
    const Eigen::Vector3f position(0.1f * (v % 5), 0.0f, 0.1f * (v / 5));
    const Eigen::Vector3f normal =
        Eigen::Vector3f(0.3f * uniform(random), 1.0f, 0.3f * uniform(random)).normalized();
    auto& obs = segment.observations[v];
    auto add = [&](const Eigen::Vector3f& direction) {
      if (normal.dot(direction) <= 0.05f) return;
      obs.emplace_back(observed(m, position, normal, direction, lights).cwiseMin(clip), direction,
                       0);
    };
    for (int k = 0; k < 16; ++k)
      add(Eigen::Vector3f(uniform(random), 0.2f + std::abs(uniform(random)), uniform(random))
              .normalized());
    for (const auto& light : lights)
      for (int k = 0; k < 2; ++k) {
        const Eigen::Vector3f wi = (light.position.cast<float>() - position).normalized();
        const Eigen::Vector3f mirror = 2 * normal.dot(wi) * normal - wi;
        add((mirror + 0.15f * Eigen::Vector3f(uniform(random), uniform(random), uniform(random)))
                .normalized());
      }
    segment.voxels.push_back({nullptr, int(obs.size()), position, normal, PointLighting{}});
  }
  for (int v = 0; v < 25; ++v) segment.voxels[v].observations = segment.observations[v].data();
  return segment;
}

int stored(const Segment& segment) {
  int count = 0;
  for (const FitVoxel& voxel : segment.voxels) count += voxel.count;
  return count;
}

TEST(SpecularFit, RecoversTheLobeDespiteSpatiallyVaryingAlbedo) {
  const auto lights = two_lights();
  for (const float alpha : {0.05f, 0.12f, 0.3f}) {
    const Eigen::Vector3f ks(0.2f, 0.15f, 0.1f);
    const Segment segment = render_segment(ks, alpha, lights);
    const auto fit = fit_specular(segment.voxels, lights);
    ASSERT_TRUE(fit.has_value()) << alpha;
    EXPECT_NEAR(fit->alpha, alpha, 0.01f * alpha);
    EXPECT_TRUE(fit->ks.isApprox(ks, 0.02f)) << fit->ks.transpose();
    EXPECT_GT(fit->explained, 0.999f);
    EXPECT_EQ(fit->observations, stored(segment)) << "every observation is above the surface";
  }
}

TEST(SpecularFit, LeavesSaturatedObservationsOut) {
  const auto lights = two_lights();
  const Eigen::Vector3f ks(0.3f, 0.3f, 0.3f);
  const float alpha = 0.08f;
  const Segment segment = render_segment(ks, alpha, lights, 1.0f);  // an 8-bit sensor clips at 1
  SpecularFitParams params;
  params.saturated_radiance = 0.99f;
  const auto fit = fit_specular(segment.voxels, lights, params);
  ASSERT_TRUE(fit.has_value());
  EXPECT_LT(fit->observations, stored(segment)) << "some highlights clip";
  EXPECT_NEAR(fit->alpha, alpha, 0.02f * alpha);
  EXPECT_TRUE(fit->ks.isApprox(ks, 0.03f)) << fit->ks.transpose();
}

// The segment of render_segment() under four times brighter lights, clipped at 1 (most
// highlight peaks clip), with every voxel's normal tilted `off_deg` in a random direction, as a
// plane fit's normals are on a curved object.
Segment clipped_segment_with_normal_error(const Eigen::Vector3f& ks, float alpha,
                                          const std::vector<render::PointLight>& lights,
                                          float off_deg) {
  Segment segment = render_segment(ks, alpha, lights, 1.0f);
  std::mt19937 random(11);
  std::uniform_real_distribution<float> angle(0.0f, float(2 * M_PI));
  const float off = float(off_deg * M_PI / 180);
  for (FitVoxel& voxel : segment.voxels) {
    const Eigen::Vector3f t1 = voxel.normal.unitOrthogonal(), t2 = voxel.normal.cross(t1);
    const float phi = angle(random);
    voxel.normal =
        std::cos(off) * voxel.normal + std::sin(off) * (std::cos(phi) * t1 + std::sin(phi) * t2);
  }
  return segment;
}

TEST(SpecularFit, ClippedHighlightsBoundTheLobeFromBelow) {
  auto lights = two_lights();
  for (auto& light : lights) light.intensity *= 4.0f;
  const Eigen::Vector3f ks(0.2f, 0.2f, 0.2f);
  const float alpha = 0.08f;
  SpecularFitParams bounded;
  bounded.saturated_radiance = 0.99f;
  SpecularFitParams left_out = bounded;
  left_out.clipped_as_bounds = false;

  // Normals 1 degree off: the unclipped flanks alone take the highlights for a weaker lobe; the
  // clipped peaks, which the lobe must reach, pull ks back up.
  const Segment slightly_off = clipped_segment_with_normal_error(ks, alpha, lights, 1.0f);
  const auto with_bounds = fit_specular(slightly_off.voxels, lights, bounded);
  const auto without = fit_specular(slightly_off.voxels, lights, left_out);
  ASSERT_TRUE(with_bounds.has_value());
  ASSERT_TRUE(without.has_value());
  EXPECT_LT(without->ks.x(), 0.65f * ks.x()) << "flanks alone: too weak a lobe";
  EXPECT_TRUE(with_bounds->ks.isApprox(ks, 0.15f)) << with_bounds->ks.transpose();
  EXPECT_EQ(with_bounds->observations, without->observations) << "bounds are not data";

  // Normals 2 degrees off: the flanks alone give a third of the true ks and look like a good fit
  // (explaining 60 % of the variation); no lobe of the searched range reaches the clipped peaks
  // and fits the flanks, so with the bounds there is no fit, and the network's estimate stands.
  const Segment off = clipped_segment_with_normal_error(ks, alpha, lights, 2.0f);
  const auto misled = fit_specular(off.voxels, lights, left_out);
  ASSERT_TRUE(misled.has_value());
  EXPECT_LT(misled->ks.x(), 0.5f * ks.x());
  EXPECT_FALSE(fit_specular(off.voxels, lights, bounded).has_value());
}

TEST(SpecularFit, AMatteOrNoisySegmentHasNoFit) {
  const auto lights = two_lights();
  // Diffuse: every voxel's observations are equal, there is nothing to explain.
  Segment matte = render_segment(Eigen::Vector3f::Zero(), 0.1f, lights);
  EXPECT_FALSE(fit_specular(matte.voxels, lights).has_value());
  // Diffuse plus noise unrelated to any lobe: a lobe explains little of it.
  std::mt19937 random(3);
  std::normal_distribution<float> noise(0.0f, 0.02f);
  for (auto& obs : matte.observations)
    for (Observation& o : obs)
      o = Observation(o.colour() + Eigen::Vector3f(noise(random), noise(random), noise(random)),
                      o.direction(), o.frame());
  EXPECT_FALSE(fit_specular(matte.voxels, lights).has_value());
  // No light, no voxels, single observations: nothing to fit either.
  EXPECT_FALSE(fit_specular(matte.voxels, {}).has_value());
  EXPECT_FALSE(fit_specular({}, lights).has_value());
  std::vector<FitVoxel> single = matte.voxels;
  for (FitVoxel& voxel : single) voxel.count = 1;
  EXPECT_FALSE(fit_specular(single, lights).has_value());
}

}  // namespace
}  // namespace glint::reflectance
