#include "reflectance/albedo_refinement.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <optional>
#include <random>
#include <utility>
#include <vector>

#include "core/error.h"
#include "reflectance/ward_observations.h"

namespace glint::reflectance {
namespace {

using test_support::observed;

// Eq. (7) over a voxel's observations: observe_diffuse(), then solve_albedo().
template <class... Args>
std::optional<RefinedAlbedo> refine_albedo(Args&&... args) {
  const auto diffuse = observe_diffuse(std::forward<Args>(args)...);
  return diffuse ? solve_albedo(*diffuse) : std::nullopt;
}

// `count` views all round (`step` radians apart in azimuth) of a surface facing +y, rising from
// `rise` over the horizontal by 0.1 per view, each seeing radiance(direction).
template <class Radiance>
std::vector<Observation> views_all_round(int count, float step, float rise, Radiance&& radiance) {
  std::vector<Observation> obs;
  for (int k = 0; k < count; ++k) {
    const Eigen::Vector3f direction =
        Eigen::Vector3f(std::cos(step * k), rise + 0.1f * k, std::sin(step * k)).normalized();
    obs.emplace_back(radiance(direction), direction, k);
  }
  return obs;
}

TEST(AlbedoRefinement, RecoversTheDiffuseAlbedoOfARenderedVoxel) {
  render::WardMaterial m;
  m.kd = {0.6f, 0.3f, 0.1f};
  m.ks = {0.2f, 0.25f, 0.3f};
  m.alpha = 0.08f;
  std::vector<render::PointLight> lights(2);
  lights[0].position = {0.5, 2.0, 0.3};
  lights[0].intensity = {3, 3, 3};
  lights[1].position = {-1.0, 1.5, -0.5};
  lights[1].intensity = {1.0f, 0.8f, 0.6f};
  const Eigen::Vector3f position(0.1f, 0.0f, 0.2f), normal = Eigen::Vector3f::UnitY();
  std::vector<Observation> obs;
  for (int k = 0; k < 12; ++k) {  // views all round, some close to the mirror direction
    const Eigen::Vector3f direction =
        Eigen::Vector3f(std::cos(0.5f * k), 0.4f + 0.1f * k, std::sin(0.5f * k)).normalized();
    obs.emplace_back(observed(m, position, normal, direction, lights), direction, k);
  }
  // And the mirror direction of the first light, where the specular lobe dominates.
  const Eigen::Vector3f wi = (lights[0].position.cast<float>() - position).normalized();
  const Eigen::Vector3f mirror = 2 * normal.dot(wi) * normal - wi;
  obs.emplace_back(observed(m, position, normal, mirror, lights), mirror, 12);
  const auto refined =
      refine_albedo(obs.data(), int(obs.size()), position, normal, lights, m.ks, m.alpha);
  ASSERT_TRUE(refined.has_value());
  // Exact up to the observations' storage: binary16 colours, 2^-11 relative.
  EXPECT_TRUE(refined->kd.isApprox(m.kd, 1e-3f)) << refined->kd.transpose();

  // Ignoring the specular part over-estimates kd: the refinement does use ks and alpha.
  const auto diffuse_only = refine_albedo(obs.data(), int(obs.size()), position, normal, lights,
                                          Eigen::Vector3f::Zero(), m.alpha);
  EXPECT_GT(diffuse_only->kd.x(), m.kd.x() + 0.01f);
}

// A voxel at the origin facing +y under one point light, of the material (kd, ks 0.2-0.3,
// alpha 0.1), and what a camera sees of it.
struct LitVoxel {
  LitVoxel(const Eigen::Vector3f& kd, float ks, const Eigen::Vector3d& light) {
    material.kd = kd;
    material.ks = Eigen::Vector3f::Constant(ks);
    material.alpha = 0.1f;
    lights[0].position = light;
    lights[0].intensity = {2, 2, 2};
  }
  Eigen::Vector3f seen_from(const Eigen::Vector3f& direction) const {
    return observed(material, position, normal, direction, lights);
  }
  // Views all round, `step` radians apart in azimuth, 45 degrees above the surface.
  Eigen::Vector3f view(int k, float step) const {
    return Eigen::Vector3f(std::cos(step * k), 1.0f, std::sin(step * k)).normalized();
  }
  std::optional<RefinedAlbedo> refine(const std::vector<Observation>& obs, AlbedoAverage average,
                                      float saturated_radiance = INFINITY) const {
    return refine_albedo(obs.data(), int(obs.size()), position, normal, lights, material.ks,
                         material.alpha, average, saturated_radiance);
  }
  render::WardMaterial material;
  std::vector<render::PointLight> lights{1};
  const Eigen::Vector3f position = Eigen::Vector3f::Zero(), normal = Eigen::Vector3f::UnitY();
};

TEST(AlbedoRefinement, MedianIgnoresAMispredictedHighlight) {
  const LitVoxel voxel({0.5f, 0.4f, 0.3f}, 0.2f, {0.3, 1.5, 0.2});
  std::vector<Observation> obs;
  for (int k = 0; k < 9; ++k) {
    const Eigen::Vector3f direction = voxel.view(k, 0.7f);
    // Observation 4: a highlight the segment's ks and alpha do not predict.
    obs.emplace_back(voxel.seen_from(direction) * (k == 4 ? 3.0f : 1.0f), direction, k);
  }
  const auto median = voxel.refine(obs, AlbedoAverage::median);
  const auto mean = voxel.refine(obs, AlbedoAverage::mean);
  ASSERT_TRUE(median && mean);
  // Each clean observation alone gives kd exactly; the median is one of them.
  const Eigen::Vector3f& kd = voxel.material.kd;
  EXPECT_TRUE(median->kd.isApprox(kd, 1e-3f)) << median->kd.transpose();  // binary16 colours
  EXPECT_GT(mean->kd.x(), kd.x() + 0.05f);
  EXPECT_EQ(parse_albedo_average("median"), AlbedoAverage::median);
  EXPECT_THROW(parse_albedo_average("mode"), Error);
}

TEST(AlbedoRefinement, ClippedObservationsCountOnlyWhereAllClipped) {
  const LitVoxel voxel({0.6f, 0.3f, 0.1f}, 0.3f, {0.2, 1.0, 0.1});
  // Eight views all round, and one at the light's mirror direction, whose highlight an 8-bit
  // sensor clips at `saturated` (in every channel).
  std::vector<Observation> obs;
  for (int k = 0; k < 8; ++k)
    obs.emplace_back(voxel.seen_from(voxel.view(k, 0.8f)), voxel.view(k, 0.8f), k);
  const Eigen::Vector3f wi = voxel.lights[0].position.cast<float>().normalized();
  const Eigen::Vector3f mirror = 2 * voxel.normal.dot(wi) * voxel.normal - wi;
  // A power of two, which the observation's binary16 colour holds exactly.
  const float saturated =
      std::exp2(std::floor(std::log2(0.5f * voxel.seen_from(mirror).minCoeff())));
  ASSERT_GT(saturated, 2 * voxel.seen_from(voxel.view(0, 0.8f)).maxCoeff());
  obs.emplace_back(Eigen::Vector3f::Constant(saturated), mirror, 8);

  // Left out, the others give kd exactly; taken in, the clipped one drags the mean down.
  const auto clean = voxel.refine(obs, AlbedoAverage::mean, saturated);
  const auto dragged = voxel.refine(obs, AlbedoAverage::mean);
  ASSERT_TRUE(clean && dragged);
  EXPECT_FALSE(clean->lower_bound);
  EXPECT_FALSE(dragged->lower_bound);
  const Eigen::Vector3f& kd = voxel.material.kd;
  EXPECT_TRUE(clean->kd.isApprox(kd, 1e-3f)) << clean->kd.transpose();  // binary16 colours
  EXPECT_LT(dragged->kd.x(), kd.x() - 0.05f);

  // Where every observation clipped, they are all there is: the same as taking them in, and
  // marked as a lower bound.
  const std::vector<Observation> only_clipped{obs.back()};
  const auto lower_bound = voxel.refine(only_clipped, AlbedoAverage::mean, saturated);
  const auto taken = voxel.refine(only_clipped, AlbedoAverage::mean);
  ASSERT_TRUE(lower_bound && taken);
  EXPECT_EQ(lower_bound->kd, taken->kd);
  EXPECT_TRUE(lower_bound->lower_bound);
  EXPECT_FALSE(taken->lower_bound);
  EXPECT_LT(lower_bound->kd.x(), kd.x());
}

TEST(AlbedoRefinement, MedianIsThePerChannelMedianForEveryCount) {
  // Diffuse-only observations (ks 0) under one light straight above: observation j's eq. (7)
  // albedo is its colour * pi / E, so the result is the per-channel median of those.
  std::vector<render::PointLight> lights(1);
  lights[0].position = {0, 1, 0};
  lights[0].intensity = {1, 1, 1};  // E = 1 at the origin
  const Eigen::Vector3f normal = Eigen::Vector3f::UnitY();
  std::mt19937 random(7);
  std::uniform_real_distribution<float> uniform(0.0f, 1.0f);
  // Counts across the 32 of the sorting network; few distinct values, so that ties occur, and
  // values spread over [0, 1].
  for (const bool ties : {true, false})
    for (int n = 1; n <= 40; ++n) {
      std::vector<Observation> obs;
      std::array<std::vector<float>, 3> albedos;
      for (int k = 0; k < n; ++k) {
        const Eigen::Vector3f direction =
            Eigen::Vector3f(uniform(random) - 0.5f, 1, uniform(random) - 0.5f).normalized();
        Eigen::Vector3f colour;
        for (int c = 0; c < 3; ++c)
          colour[c] = (ties ? std::round(uniform(random) * 8) / 8 : uniform(random)) / float(M_PI);
        obs.emplace_back(colour, direction, k);
        // The albedo of the colour as stored (binary16).
        for (int c = 0; c < 3; ++c) albedos[c].push_back(obs.back().colour()[c] * float(M_PI));
      }
      const auto refined = refine_albedo(obs.data(), n, Eigen::Vector3f::Zero(), normal, lights,
                                         Eigen::Vector3f::Zero(), 0.1f, AlbedoAverage::median);
      ASSERT_TRUE(refined);
      for (int c = 0; c < 3; ++c) {
        std::sort(albedos[c].begin(), albedos[c].end());
        const float expected =
            n % 2 ? albedos[c][n / 2] : 0.5f * (albedos[c][n / 2 - 1] + albedos[c][n / 2]);
        EXPECT_NEAR(refined->kd[c], expected, 1e-6f)
            << n << " observations, channel " << c << (ties ? ", with ties" : "");
      }
    }
}

TEST(AlbedoRefinement, LightCosineIsTheEffectiveIncidenceOfTheLights) {
  const Observation o(Eigen::Vector3f::Constant(0.5f), Eigen::Vector3f::UnitY(), 0);
  const Eigen::Vector3f normal = Eigen::Vector3f::UnitY();
  const auto light_cosine = [&](const std::vector<render::PointLight>& lights) {
    const RefinedAlbedo refined = *refine_albedo(&o, 1, Eigen::Vector3f::Zero(), normal, lights,
                                                 Eigen::Vector3f::Zero(), 0.1f);
    // The tangent of the same angle.
    EXPECT_NEAR(
        refined.light_tangent,
        std::sqrt(1 - refined.light_cosine() * refined.light_cosine()) / refined.light_cosine(),
        1e-4f);
    return refined.light_cosine();
  };
  // One light at 60 degrees from the normal: cos 60.
  std::vector<render::PointLight> lights(1);
  lights[0].position = {std::sqrt(3.0), 1.0, 0.0};
  lights[0].intensity = {2, 2, 2};
  EXPECT_NEAR(light_cosine(lights), 0.5f, 1e-5f);
  // Two equal lights at 0 and 80 degrees from the normal, the same distance away:
  // t = (0 + sin 80) / (1 + cos 80).
  lights.resize(2);
  const double theta = 80 * M_PI / 180;
  lights[0].position = {0, 2, 0};
  lights[1].position = {2 * std::sin(theta), 2 * std::cos(theta), 0};
  lights[1].intensity = lights[0].intensity;
  const double t = std::sin(theta) / (1 + std::cos(theta));
  EXPECT_NEAR(light_cosine(lights), 1 / std::sqrt(1 + t * t), 1e-5);
  // A grazing light alone.
  lights.erase(lights.begin());
  EXPECT_NEAR(light_cosine(lights), std::cos(theta), 1e-5);
}

TEST(AlbedoRefinement, GrazingLightWeighsAnAlbedoByTheInverseOfItsVariance) {
  // Light at 45 degrees or steeper: full weight.
  EXPECT_EQ(refined_albedo_weight(0.0f), 1.0f);
  EXPECT_EQ(refined_albedo_weight(1.0f), 1.0f);
  // Beyond, the albedo's error under a normal error grows with the tangent, its variance with
  // its square: cosine 0.3 (tangent 3.18) weighs about a tenth.
  const float tangent = std::sqrt(1 - 0.3f * 0.3f) / 0.3f;
  EXPECT_NEAR(refined_albedo_weight(tangent), 0.09f / 0.91f, 1e-6f);
  EXPECT_NEAR(refined_albedo_weight(3.0f), 1.0f / 9, 1e-7f);
}

TEST(AlbedoRefinement, AnAlbedoMoreThanTheRatioFromItsSegmentsIsNotExplainedByTheLights) {
  // Within a factor 3 either way of the segment's 0.4: explained.
  EXPECT_TRUE(explained_by_light(0.134f, 0.4f, 3));
  EXPECT_TRUE(explained_by_light(1.0f, 0.4f, 3));
  // A shadowed voxel read as lit: under a third of the segment's.
  EXPECT_FALSE(explained_by_light(0.13f, 0.4f, 3));
  EXPECT_FALSE(explained_by_light(0.0f, 0.4f, 3));
  // More than three times as bright.
  EXPECT_FALSE(explained_by_light(0.5f, 0.12f, 3));
  // Ratio 0, or no reference yet: everything, as the paper.
  EXPECT_TRUE(explained_by_light(0.0f, 0.4f, 0));
  EXPECT_TRUE(explained_by_light(0.0f, NAN, 3));
}

TEST(AlbedoRefinement, TooDarkAlbedosLackLightUnlessTheyAreLowerBounds) {
  // Within the ratio: an estimate, lacking no light.
  AlbedoVerdict verdict = judge_albedo(0.3f, false, 0.4f, 3);
  EXPECT_TRUE(verdict.estimate);
  EXPECT_EQ(verdict.light_shortfall, 0.0f);
  // A voxel read as lit in a shadow: no estimate, and three quarters of its light missing.
  verdict = judge_albedo(0.1f, false, 0.4f, 3);
  EXPECT_FALSE(verdict.estimate);
  EXPECT_FLOAT_EQ(verdict.light_shortfall, 0.75f);
  // Too bright: no estimate, no light missing.
  verdict = judge_albedo(0.9f, false, 0.2f, 3);
  EXPECT_FALSE(verdict.estimate);
  EXPECT_EQ(verdict.light_shortfall, 0.0f);
  // Every observation clipped: a bound below the reference is no estimate, even within the
  // ratio, and it lacks no light; one above the reference is kept.
  for (const float bound : {0.1f, 0.3f}) {
    verdict = judge_albedo(bound, true, 0.4f, 3);
    EXPECT_FALSE(verdict.estimate) << bound;
    EXPECT_EQ(verdict.light_shortfall, 0.0f) << bound;
  }
  EXPECT_TRUE(judge_albedo(0.5f, true, 0.4f, 3).estimate);
  // No reference yet, or the test off: everything, as the paper.
  EXPECT_TRUE(judge_albedo(0.0f, true, NAN, 3).estimate);
  EXPECT_TRUE(judge_albedo(0.0f, true, 0.4f, 0).estimate);
}

TEST(AlbedoRefinement, ALobeThatPredictsTooMuchHighlightLacksNoLight) {
  // A matte wall seen near the mirror direction of its one light.
  render::WardMaterial wall;
  wall.kd = {0.6f, 0.6f, 0.6f};
  wall.ks = {0.02f, 0.02f, 0.02f};
  wall.alpha = 0.3f;
  std::vector<render::PointLight> lights(1);
  lights[0].position = {0.0, 1.0, -0.5};
  lights[0].intensity = {2, 2, 2};
  const Eigen::Vector3f position = Eigen::Vector3f::Zero(), normal = Eigen::Vector3f::UnitY();
  const Eigen::Vector3f wi = (lights[0].position.cast<float>() - position).normalized();
  const Eigen::Vector3f mirror = 2 * normal.dot(wi) * normal - wi;
  std::vector<Observation> obs;
  for (int k = 0; k < 7; ++k) {
    const Eigen::Vector3f direction =
        (mirror + 0.03f * Eigen::Vector3f(std::cos(0.9f * k), 0, std::sin(0.9f * k))).normalized();
    obs.emplace_back(observed(wall, position, normal, direction, lights), direction, k);
  }
  const float reference = 0.6f, max_ratio = 3;
  // A glossy lobe (a network's guess) takes out more than the wall reflects: eq. (7) leaves it
  // dark, as an unseen shadow would.
  const Eigen::Vector3f glossy(0.3f, 0.3f, 0.3f);
  const auto dark = refine_albedo(obs.data(), int(obs.size()), position, normal, lights, glossy,
                                  0.05f, AlbedoAverage::median);
  ASSERT_TRUE(dark);
  const AlbedoVerdict verdict = judge_albedo(dark->kd.maxCoeff(), false, reference, max_ratio);
  ASSERT_GT(verdict.light_shortfall, 0.0f);
  // Without the lobe the observations hold the light: no light lacking, still no estimate.
  const auto bare = refine_albedo(obs.data(), int(obs.size()), position, normal, lights,
                                  Eigen::Vector3f::Zero(), 0.05f, AlbedoAverage::median);
  ASSERT_TRUE(bare);
  EXPECT_NEAR(bare->kd.x(), 0.6f, 0.1f);  // the wall's own highlight on top
  const AlbedoVerdict rejudged =
      judge_without_lobe(verdict, bare->kd.maxCoeff(), reference, max_ratio);
  EXPECT_FALSE(rejudged.estimate);
  EXPECT_EQ(rejudged.light_shortfall, 0.0f);
  // In an unseen shadow the observations lack the light with or without the lobe: it stays.
  std::vector<Observation> shadowed;
  for (const Observation& o : obs)
    shadowed.emplace_back(0.05f * o.colour(), o.direction(), std::uint32_t(shadowed.size()));
  const auto in_shadow =
      refine_albedo(shadowed.data(), int(shadowed.size()), position, normal, lights,
                    Eigen::Vector3f::Zero(), 0.05f, AlbedoAverage::median);
  ASSERT_TRUE(in_shadow);
  EXPECT_EQ(
      judge_without_lobe(verdict, in_shadow->kd.maxCoeff(), reference, max_ratio).light_shortfall,
      verdict.light_shortfall);
}

TEST(AlbedoRefinement, UnlitOrUnseenVoxelsHaveNoEstimate) {
  std::vector<render::PointLight> below(1);
  below[0].position = {0, -1, 0};
  Observation o(Eigen::Vector3f::Constant(0.5f), Eigen::Vector3f::UnitY(), 0);
  const Eigen::Vector3f normal = Eigen::Vector3f::UnitY();
  EXPECT_FALSE(
      refine_albedo(&o, 1, Eigen::Vector3f::Zero(), normal, below, Eigen::Vector3f::Zero(), 0.1f));
  std::vector<render::PointLight> above(1);
  above[0].position = {0, 1, 0};
  EXPECT_FALSE(
      refine_albedo(&o, 0, Eigen::Vector3f::Zero(), normal, above, Eigen::Vector3f::Zero(), 0.1f));
  o = Observation(o.colour(), -Eigen::Vector3f::UnitY(), 0);  // seen from below the surface
  EXPECT_FALSE(
      refine_albedo(&o, 1, Eigen::Vector3f::Zero(), normal, above, Eigen::Vector3f::Zero(), 0.1f));
}

// Observed radiance = kd / pi * (E_direct + E_indirect) + specular, with E_direct over the
// lights that reach the voxel: eq. (7) divides by that total and recovers kd, where the paper's
// division by every light's irradiance reads a shadowed, indirectly lit voxel far too dark.
TEST(AlbedoRefinement, ShadowedLightsAndIndirectLightAreTakenOutOfEquationSeven) {
  render::WardMaterial m;
  m.kd = {0.6f, 0.3f, 0.1f};
  m.ks = {0.2f, 0.2f, 0.2f};
  m.alpha = 0.1f;
  std::vector<render::PointLight> lights(2);
  lights[0].position = {0.5, 2.0, 0.3};
  lights[0].intensity = {3, 3, 3};
  lights[1].position = {-1.0, 1.5, -0.5};
  lights[1].intensity = {2, 2, 2};
  const Eigen::Vector3f position(0.1f, 0.0f, 0.2f), normal = Eigen::Vector3f::UnitY();
  const PointLighting lighting{.lit = kAllLights & ~LightMask{2},  // light 1 shadowed
                               .indirect = Eigen::Vector3f(0.4f, 0.3f, 0.2f)};
  const std::vector<render::PointLight> reaching{lights[0]};
  const std::vector<Observation> obs =
      views_all_round(10, 0.6f, 0.5f, [&](const Eigen::Vector3f& direction) -> Eigen::Vector3f {
        return observed(m, position, normal, direction, reaching) +
               m.kd.cwiseProduct(lighting.indirect) / float(M_PI);
      });
  const auto refined = refine_albedo(obs.data(), int(obs.size()), position, normal, lights, m.ks,
                                     m.alpha, AlbedoAverage::median, INFINITY, lighting);
  ASSERT_TRUE(refined.has_value());
  EXPECT_TRUE(refined->kd.isApprox(m.kd, 2e-3f)) << refined->kd.transpose();
  // Leaving the indirect light out reads the albedo too bright; the shadow, too dark.
  const auto direct_only =
      refine_albedo(obs.data(), int(obs.size()), position, normal, lights, m.ks, m.alpha,
                    AlbedoAverage::median, INFINITY, PointLighting{.lit = lighting.lit});
  EXPECT_GT(direct_only->kd.x(), 1.1f * m.kd.x());
  const auto unshadowed =
      refine_albedo(obs.data(), int(obs.size()), position, normal, lights, m.ks, m.alpha,
                    AlbedoAverage::median, INFINITY, PointLighting{.indirect = lighting.indirect});
  EXPECT_LT(unshadowed->kd.x(), 0.9f * m.kd.x());

  // Every light shadowed: the indirect light alone gives the albedo.
  const PointLighting dark{.lit = 0, .indirect = Eigen::Vector3f(0.4f, 0.3f, 0.2f)};
  std::vector<Observation> unlit;
  for (int k = 0; k < 5; ++k) {
    const Eigen::Vector3f direction =
        Eigen::Vector3f(std::cos(0.6f * k), 0.5f, std::sin(0.6f * k)).normalized();
    unlit.emplace_back(m.kd.cwiseProduct(dark.indirect) / float(M_PI), direction, k);
  }
  const auto from_indirect =
      refine_albedo(unlit.data(), int(unlit.size()), position, normal, lights, m.ks, m.alpha,
                    AlbedoAverage::mean, INFINITY, dark);
  ASSERT_TRUE(from_indirect.has_value());
  EXPECT_TRUE(from_indirect->kd.isApprox(m.kd, 2e-3f)) << from_indirect->kd.transpose();
  EXPECT_FLOAT_EQ(from_indirect->light_cosine(), 1.0f);  // indirect light counts as head-on
  // Neither direct nor indirect light: no estimate.
  EXPECT_FALSE(refine_albedo(unlit.data(), int(unlit.size()), position, normal, lights, m.ks,
                             m.alpha, AlbedoAverage::mean, INFINITY, PointLighting{.lit = 0})
                   .has_value());
}

// The specular reflection of indirect light as an even sky (LightTransportParams::
// indirect_specular): the lobe reflects ks times its radiance times the lobe's directional
// albedo (render::ward_lobe_albedo()), and eq. (7) takes that out before dividing by the
// irradiance.
TEST(AlbedoRefinement, IndirectLightTheLobeMirrorsIsTakenOutOfEquationSeven) {
  const LitVoxel voxel({0.3f, 0.2f, 0.1f}, 0.4f, {0.5, 2.0, 0.3});
  const render::WardMaterial& m = voxel.material;
  const Eigen::Vector3f indirect(0.6f, 0.5f, 0.4f);
  const PointLighting glossy{.indirect = indirect, .indirect_radiance = indirect / float(M_PI)};
  const std::vector<Observation> obs =
      views_all_round(8, 0.7f, 0.6f, [&](const Eigen::Vector3f& direction) -> Eigen::Vector3f {
        const Eigen::Vector3f mirrored =
            render::ward_lobe_albedo(voxel.normal.dot(direction), m.alpha) *
            m.ks.cwiseProduct(indirect);
        return voxel.seen_from(direction) + (m.kd.cwiseProduct(indirect) + mirrored) / float(M_PI);
      });
  const auto refine = [&](const PointLighting& lighting) {
    return refine_albedo(obs.data(), int(obs.size()), voxel.position, voxel.normal, voxel.lights,
                         m.ks, m.alpha, AlbedoAverage::median, INFINITY, lighting);
  };
  const auto refined = refine(glossy);
  ASSERT_TRUE(refined.has_value());
  EXPECT_TRUE(refined->kd.isApprox(m.kd, 2e-3f)) << refined->kd.transpose();
  // Taken for albedo without it: the blue channel, where ks is largest against kd, by half.
  EXPECT_GT(refine({.indirect = indirect})->kd.z(), 1.5f * m.kd.z());

  // Each observation's lobe mirroring a radiance of its own (PointLighting::mirrored: what its
  // lobe rays met), the even sky where that is unknown (NaN).
  std::vector<Eigen::Vector3f> mirrored;
  const std::vector<Observation> directional =
      views_all_round(8, 0.7f, 0.6f, [&](const Eigen::Vector3f& direction) -> Eigen::Vector3f {
        const int k = int(mirrored.size());
        mirrored.push_back(k == 3 ? Eigen::Vector3f::Constant(NAN)
                                  : Eigen::Vector3f(indirect * (0.2f * float(k % 4))));
        const Eigen::Vector3f seen_in_lobe = k == 3 ? glossy.indirect_radiance : mirrored.back();
        return voxel.seen_from(direction) + m.kd.cwiseProduct(indirect) / float(M_PI) +
               render::ward_lobe_albedo(voxel.normal.dot(direction), m.alpha) *
                   m.ks.cwiseProduct(seen_in_lobe);
      });
  PointLighting mirroring = glossy;
  mirroring.mirrored = mirrored;
  const auto refined_mirroring =
      refine_albedo(directional.data(), int(directional.size()), voxel.position, voxel.normal,
                    voxel.lights, m.ks, m.alpha, AlbedoAverage::median, INFINITY, mirroring);
  ASSERT_TRUE(refined_mirroring.has_value());
  EXPECT_TRUE(refined_mirroring->kd.isApprox(m.kd, 2e-3f)) << refined_mirroring->kd.transpose();
}

TEST(AlbedoRefinement, UnseenIrradianceCompletesTheLightOfAVoxelNoLightReaches) {
  // Every light shadowed, no gathered light: the observations still give the diffuse radiance,
  // and the segment's unseen irradiance the albedo.
  const Eigen::Vector3f kd(0.5f, 0.4f, 0.2f), unseen(0.3f, 0.3f, 0.25f);
  std::vector<render::PointLight> lights(1);
  lights[0].position = {0, 2, 0};
  lights[0].intensity = {3, 3, 3};
  std::vector<Observation> obs;
  for (int k = 0; k < 4; ++k)
    obs.emplace_back(kd.cwiseProduct(unseen) / float(M_PI),
                     Eigen::Vector3f(0.3f * float(k), 1, 0.1f).normalized(), k);
  const auto observed = observe_diffuse(
      obs.data(), int(obs.size()), Eigen::Vector3f::Zero(), Eigen::Vector3f::UnitY(), lights,
      Eigen::Vector3f::Zero(), 0.1f, AlbedoAverage::median, INFINITY, PointLighting{.lit = 0});
  ASSERT_TRUE(observed.has_value());
  EXPECT_TRUE(observed->irradiance.isZero());
  EXPECT_FALSE(solve_albedo(*observed).has_value());
  const auto refined = solve_albedo(*observed, unseen);
  ASSERT_TRUE(refined.has_value());
  EXPECT_TRUE(refined->kd.isApprox(kd, 1e-3f)) << refined->kd.transpose();  // half-float colours
  // The unseen light is the segment's estimate, not the gather's: it does not count against
  // the voxel's trust (RefinedAlbedo::indirect_share).
  EXPECT_FLOAT_EQ(refined->indirect_share, 0.0f);
}

TEST(AlbedoRefinement, AVoxelNoLightReachesSamplesTheGathersShortfall) {
  // True indirect light E, of which the gather found half (scaled by whatever the transport's
  // scale is now: the sample compares with the gather before the scale).
  const Eigen::Vector3f kd(0.5f, 0.4f, 0.2f), truth(0.4f, 0.3f, 0.3f), gathered = truth / 2;
  std::vector<render::PointLight> lights(1);
  lights[0].position = {0, 2, 0};
  lights[0].intensity = {3, 3, 3};
  const auto observe = [&](const Eigen::Vector3f& radiance, const PointLighting& lighting) {
    std::vector<Observation> obs;
    for (int k = 0; k < 4; ++k)
      obs.emplace_back(radiance, Eigen::Vector3f(0.3f * float(k), 1, 0.1f).normalized(), k);
    return *observe_diffuse(obs.data(), int(obs.size()), Eigen::Vector3f::Zero(),
                            Eigen::Vector3f::UnitY(), lights, Eigen::Vector3f::Zero(), 0.1f,
                            AlbedoAverage::median, INFINITY, lighting);
  };
  const Eigen::Vector3f radiance = kd.cwiseProduct(truth) / float(M_PI);
  const float reference = kd.maxCoeff();
  for (const float scale : {0.0f, 1.5f}) {
    const PointLighting shadowed{.lit = 0, .indirect = gathered * scale};
    EXPECT_NEAR(indirect_scale_sample(observe(radiance, shadowed), gathered, reference), 2.0f,
                2e-3f)
        << scale;  // half-float colours
  }
  // Black where no light reaches: no bounced light, the gather takes nothing out.
  EXPECT_FLOAT_EQ(
      indirect_scale_sample(observe(Eigen::Vector3f::Zero(), {.lit = 0}), gathered, reference),
      0.0f);
  // The light reaches it: its radiance is not the indirect light's alone.
  EXPECT_TRUE(std::isnan(indirect_scale_sample(observe(radiance, {}), gathered, reference)));
  // No gathered light in a channel, or no reference: no sample.
  EXPECT_TRUE(std::isnan(indirect_scale_sample(observe(radiance, {.lit = 0}),
                                               Eigen::Vector3f(0.2f, 0.0f, 0.1f), reference)));
  EXPECT_TRUE(
      std::isnan(indirect_scale_sample(observe(radiance, {.lit = 0}), gathered, std::nanf(""))));
}

TEST(AlbedoRefinement, AnAlbedosErrorIsItsObservationsScatterTheGathersAndItsNormals) {
  // Diffuse-only observations (ks 0) of a surface facing +y under one light straight above
  // (E = 1 at the origin): observation j's albedo is its colour * pi.
  std::vector<render::PointLight> lights(1);
  lights[0].position = {0, 1, 0};
  lights[0].intensity = {1, 1, 1};
  const auto error_of = [&](const std::vector<float>& albedos) {
    std::vector<Observation> obs;
    for (std::size_t k = 0; k < albedos.size(); ++k) {
      const Eigen::Vector3f direction = Eigen::Vector3f(0.1f * float(k), 1, 0).normalized();
      obs.emplace_back(Eigen::Vector3f::Constant(albedos[k] / float(M_PI)), direction, int(k));
    }
    const auto refined =
        refine_albedo(obs.data(), int(obs.size()), Eigen::Vector3f::Zero(),
                      Eigen::Vector3f::UnitY(), lights, Eigen::Vector3f::Zero(), 0.1f);
    EXPECT_TRUE(refined);
    return refined ? refined->radiance_error : NAN;
  };
  // Median 0.5, absolute deviations 0.1, 0.05, 0, 0.05, 0.1 (median 0.05): the median's relative
  // standard error 1.4826 * 0.05 / 0.5 / sqrt(5).
  EXPECT_NEAR(error_of({0.4f, 0.45f, 0.5f, 0.55f, 0.6f}), 1.4826f * 0.1f / std::sqrt(5.0f), 1e-3f);
  // Observations that agree, and fewer than kMinScatterObservations: no error.
  EXPECT_EQ(error_of({0.5f, 0.5f, 0.5f, 0.5f}), 0.0f);
  EXPECT_EQ(error_of({0.4f, 0.6f}), 0.0f);
  // A minority of outliers (a voxel mostly on one face, a few views of the other) moves it
  // little; half the views on each face of a crease, much.
  EXPECT_LT(error_of({0.5f, 0.5f, 0.5f, 0.5f, 0.5f, 0.5f, 0.1f, 0.1f}), 0.01f);
  EXPECT_GT(error_of({0.5f, 0.5f, 0.5f, 0.5f, 0.1f, 0.1f, 0.1f, 0.1f}), 0.2f);

  // The scatter's, the gathered light's and the normal's errors add in quadrature.
  RefinedAlbedo refined;
  refined.radiance_error = 0.03f;
  refined.indirect_share = 0.5f;
  EXPECT_NEAR(albedo_error(refined, 0.08f, 0.0f), 0.05f, 1e-6f);
  EXPECT_NEAR(albedo_error(refined, 0.0f, 0.0f), 0.03f, 1e-6f);
  // Light at 45 degrees (t = 1) leaves a 0.04 rad normal error at 0.04; at cosine 0.2 (t = 4.9)
  // the same normal is a fifth of the albedo.
  refined.radiance_error = 0.0f;
  refined.indirect_share = 0.0f;
  refined.light_tangent = 1.0f;
  EXPECT_NEAR(albedo_error(refined, 0.08f, 0.04f), 0.04f, 1e-6f);
  refined.light_tangent = tangent_of(0.2f);
  EXPECT_NEAR(albedo_error(refined, 0.08f, 0.04f), 0.04f * std::sqrt(24.0f), 1e-5f);
  refined.radiance_error = 0.03f;
  EXPECT_NEAR(albedo_error(refined, 0.0f, 0.04f), std::hypot(0.03f, 0.04f * std::sqrt(24.0f)),
              1e-5f);
}

TEST(AlbedoRefinement, AnAlbedoShrinksTowardsItsSegmentsByTheGathersErrorOverTheSpread) {
  const Eigen::Vector3f kd(0.6f, 0.3f, 0.15f);  // brightness 0.6
  const float reference = 0.4f;
  // No gathered-light error, no spread known or no reference: eq. (7)'s albedo as it is.
  EXPECT_EQ(shrink_albedo(kd, reference, 0.0f, 0.1f), kd);
  EXPECT_EQ(shrink_albedo(kd, reference, 0.3f, std::nanf("")), kd);
  EXPECT_EQ(shrink_albedo(kd, std::nanf(""), 0.3f, 0.1f), kd);
  // Error equal to the spread: w = 1/2, the brightness at the geometric mean of the voxel's and
  // the segment's, the colour (channel ratios) kept.
  const Eigen::Vector3f half = shrink_albedo(kd, reference, 0.1f, 0.1f);
  EXPECT_NEAR(half.maxCoeff(), std::sqrt(0.6f * reference), 1e-6f);
  EXPECT_NEAR(half.y() / half.x(), 0.5f, 1e-6f);
  EXPECT_NEAR(half.z() / half.x(), 0.25f, 1e-6f);
  // An error far above the spread: the segment's brightness; far below: the voxel's own.
  EXPECT_NEAR(shrink_albedo(kd, reference, 10.0f, 0.01f).maxCoeff(), reference, 1e-5f);
  EXPECT_NEAR(shrink_albedo(kd, reference, 1e-4f, 0.5f).maxCoeff(), 0.6f, 1e-5f);
  // A uniform segment (spread 0): any error takes the segment's brightness; never above 1.
  EXPECT_NEAR(shrink_albedo(kd, reference, 0.05f, 0.0f).maxCoeff(), reference, 1e-6f);
  EXPECT_EQ(shrink_albedo(Eigen::Vector3f(0.5f, 0.45f, 0.4f), 3.0f, 1.0f, 0.0f).maxCoeff(), 1.0f);
}

}  // namespace
}  // namespace glint::reflectance
