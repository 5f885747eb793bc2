// The kd atlas's denoising and evaluation parts: the baked-texel mask and the dilation, the
// guidance from noise level and observation count, the layout's density cap, and the error
// split by observation count against known values.
#include "gltf/albedo_denoising.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>

#include "gltf/albedo_truth.h"
#include "gltf/texture_atlas.h"

namespace glint::gltf {
namespace {

// One right triangle of 1 m legs in the z = 0 plane.
struct Triangle {
  std::vector<Eigen::Vector3f> vertices{{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
  std::vector<Eigen::Vector3i> triangles{{0, 1, 2}};
  std::vector<int> group{1};
};

TEST(AlbedoAtlas, BakedMaskMarksTheTrianglesTexelsNotTheGutter) {
  const Triangle mesh;
  const AtlasParams params{.size = 32, .gutter = 2};
  AtlasLayout layout = layout_atlas(mesh.vertices, mesh.triangles, mesh.group, params);
  std::vector<std::uint8_t> baked;
  const ImageF image = bake_atlas(
      layout, mesh.vertices, [](const Eigen::Vector3f&, int) { return Eigen::Vector3f(1, 1, 1); },
      params, &baked);
  ASSERT_EQ(baked.size(), 32u * 32u);
  std::size_t baked_count = 0, gutter = 0;
  for (std::size_t i = 0; i < baked.size(); ++i) {
    baked_count += baked[i];
    if (!baked[i] && image.plane(0)[i] > 0) ++gutter;  // filled by dilation only
    if (baked[i]) {
      EXPECT_EQ(image.plane(0)[i], 1.0f);
    }
  }
  // Half of the square chart (plus the texels within one of the hypotenuse) is baked.
  EXPECT_GT(baked_count, 32u * 32u / 3);
  EXPECT_LT(baked_count, 32u * 32u * 3 / 4);
  EXPECT_GT(gutter, 0u);
}

TEST(AlbedoAtlas, DilationFillsOneRingPerPass) {
  ImageF image(5, 5, 2, 0.0f);
  image.at(2, 2, 0) = 4, image.at(2, 2, 1) = 8;
  std::vector<std::uint8_t> filled(25, 0);
  filled[2 * 5 + 2] = 1;
  dilate_atlas(image, filled, 1);
  EXPECT_EQ(image.at(1, 1, 0), 4.0f);
  EXPECT_EQ(image.at(3, 2, 1), 8.0f);
  EXPECT_EQ(image.at(0, 0, 0), 0.0f);  // two rings away
  EXPECT_EQ(filled[1 * 5 + 1], 1);
  EXPECT_EQ(filled[0], 0);
  dilate_atlas(image, filled, 1);
  EXPECT_EQ(image.at(0, 0, 0), 4.0f);
}

TEST(AlbedoAtlas, LayoutDensityIsCappedWhenAsked) {
  const Triangle mesh;
  const AtlasLayout free = layout_atlas(mesh.vertices, mesh.triangles, mesh.group, {.size = 256});
  const AtlasLayout capped = layout_atlas(mesh.vertices, mesh.triangles, mesh.group,
                                          {.size = 256, .max_texels_per_metre = 50});
  EXPECT_GT(free.texels_per_metre, 200.0f);
  EXPECT_FLOAT_EQ(capped.texels_per_metre, 50.0f);
}

TEST(AlbedoGuidance, FewObservationsMarkTexelsNoisyAndUnbakedOnesAreKept) {
  // The same noise everywhere; the right half was observed twice, the left half 30 times.
  const int w = 64, h = 32;
  ImageF kd(w, h, 3), observations(w, h, 3, 0.0f);
  std::mt19937 random(3);
  std::normal_distribution<float> noise(0.0f, 0.02f);
  std::vector<std::uint8_t> baked(std::size_t(w) * h, 1);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      for (int c = 0; c < 3; ++c) kd.at(x, y, c) = 0.5f + noise(random);
      observations.at(x, y, 0) = x < w / 2 ? 30.0f : 2.0f;
    }
  for (int x = 0; x < w; ++x) baked[x] = 0;  // the top row is not part of a chart
  const ImageF guidance = albedo_guidance(kd, observations, baked, 30);
  double left = 0, right = 0;
  int left_count = 0, right_count = 0;
  for (int y = 4; y < h - 4; ++y)
    for (int x = 4; x < w / 2 - 4; ++x, ++left_count) left += guidance.at(x, y, 0);
  for (int y = 4; y < h - 4; ++y)
    for (int x = w / 2 + 4; x < w - 4; ++x, ++right_count) right += guidance.at(x, y, 0);
  EXPECT_GT(left / left_count, 0.9);  // well observed: kept
  // 15 times the variance: at most half as trusted.
  EXPECT_LT(right / right_count, 0.5 * left / left_count);
  for (int x = 0; x < w; ++x) EXPECT_EQ(guidance.at(x, 0, 0), 1.0f);
}

TEST(AlbedoErrors, L1AndPsnrPerObservationClassAgainstKnownValues) {
  // Four texels: two well observed 0.1 off, one poorly observed 0.2 off, one without truth, and
  // one unbaked texel 0.9 off that must not count.
  ImageF atlas(5, 1, 3, 0.5f), truth(5, 1, 3, 0.6f), observations(5, 1, 3, 0.0f);
  observations.at(0, 0, 0) = 20, observations.at(1, 0, 0) = 15, observations.at(2, 0, 0) = 3;
  for (int c = 0; c < 3; ++c) {
    truth.at(2, 0, c) = 0.3f;
    truth.at(3, 0, c) = std::numeric_limits<float>::quiet_NaN();
    truth.at(4, 0, c) = 1.4f;
  }
  const std::vector<std::uint8_t> baked{1, 1, 1, 1, 0};
  const nlohmann::json errors = albedo_errors(atlas, truth, observations, baked, 15);
  EXPECT_EQ(errors["well_observed"]["texels"], 2);
  EXPECT_NEAR(errors["well_observed"]["l1"].get<double>(), 0.1, 1e-6);
  EXPECT_NEAR(errors["well_observed"]["psnr"].get<double>(), 20.0, 1e-4);
  EXPECT_EQ(errors["poorly_observed"]["texels"], 1);
  EXPECT_NEAR(errors["poorly_observed"]["l1"].get<double>(), 0.2, 1e-6);
  EXPECT_NEAR(errors["poorly_observed"]["psnr"].get<double>(), -20 * std::log10(0.2), 1e-4);
  EXPECT_EQ(errors["all"]["texels"], 3);
  EXPECT_NEAR(errors["all"]["l1"].get<double>(), 0.4 / 3, 1e-6);
}

}  // namespace
}  // namespace glint::gltf
