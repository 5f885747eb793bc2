#include "edges/synth.h"

#include <gtest/gtest.h>

#include "core/error.h"

namespace glint::edges {
namespace {

SynthParams clean_params(SynthShape shape, int points = 20000) {
  SynthParams params;
  params.shapes = {shape};
  params.min_points = params.max_points = points;
  params.noise_levels = {0.0};
  params.outlier_probability = 0.0;
  params.abc_probability = 0.0;
  params.gradient_probability = 0.0;
  return params;
}

std::array<std::size_t, 3> label_counts(const SynthCloud& cloud) {
  std::array<std::size_t, 3> counts{0, 0, 0};
  for (auto label : *cloud.cloud.get<std::uint8_t>("label")) ++counts.at(label);
  return counts;
}

TEST(Synth, SameSeedAndIndexGiveTheSameCloud) {
  SynthParams params;
  params.seed = 7;
  const SynthCloud a = synthesize_cloud(params, 3), b = synthesize_cloud(params, 3);
  ASSERT_EQ(a.cloud.size(), b.cloud.size());
  EXPECT_EQ(a.cloud.x, b.cloud.x);
  EXPECT_EQ(a.cloud.z, b.cloud.z);
  EXPECT_EQ(*a.cloud.get<std::uint8_t>("label"), *b.cloud.get<std::uint8_t>("label"));
  const SynthCloud c = synthesize_cloud(params, 4);
  EXPECT_NE(a.cloud.x, c.cloud.x);
}

// A box's sharp band holds 2 * band * (edge length) of its area: 12 edges, 4 of each size.
TEST(Synth, BoxSharpBandMatchesTheEdgeLength) {
  const SynthParams params = clean_params(SynthShape::box);
  const SynthCloud cloud = synthesize_cloud(params, 0);
  const auto counts = label_counts(cloud);
  EXPECT_EQ(counts[2], 0u);
  const auto& size = cloud.description["shape_parameters"]["size"];
  const double x = size[0], y = size[1], z = size[2];
  const double area = 2 * (x * y + y * z + x * z), edges = 4 * (x + y + z);
  const double spacing = std::sqrt(area / 20000);
  const double expected = 20000 * 2 * params.band * spacing * edges / area;
  EXPECT_NEAR(double(counts[1]), expected, 0.15 * expected);
}

TEST(Synth, OpenSheetsHaveBoundariesAndNoCreases) {
  for (SynthShape shape : {SynthShape::sheet, SynthShape::disc, SynthShape::annulus,
                           SynthShape::holed_sheet, SynthShape::wavy_sheet, SynthShape::hemisphere,
                           SynthShape::tube, SynthShape::curved_sheet, SynthShape::bend}) {
    const auto counts = label_counts(synthesize_cloud(clean_params(shape), 1));
    EXPECT_EQ(counts[1], 0u) << synth_shape_names()[int(shape)];
    EXPECT_GT(counts[2], 0u) << synth_shape_names()[int(shape)];
  }
}

TEST(Synth, ClosedShapesHaveNoBoundary) {
  for (SynthShape shape :
       {SynthShape::box, SynthShape::thin_wall, SynthShape::fractal_cube, SynthShape::stairs,
        SynthShape::cylinder, SynthShape::cone, SynthShape::frustum}) {
    const auto counts = label_counts(synthesize_cloud(clean_params(shape), 2));
    EXPECT_EQ(counts[2], 0u) << synth_shape_names()[int(shape)];
    EXPECT_GT(counts[1], 0u) << synth_shape_names()[int(shape)];
  }
  const auto sphere = label_counts(synthesize_cloud(clean_params(SynthShape::sphere), 0));
  EXPECT_EQ(sphere[1] + sphere[2], 0u);
}

TEST(Synth, OpenBoxAndCreaseHaveBothClasses) {
  for (SynthShape shape : {SynthShape::open_box, SynthShape::crease}) {
    const auto counts = label_counts(synthesize_cloud(clean_params(shape), 0));
    EXPECT_GT(counts[1], 0u);
    EXPECT_GT(counts[2], 0u);
  }
}

TEST(Synth, AbcSamplingPutsPointsOnTheEdges) {
  SynthParams params = clean_params(SynthShape::box, 5000);
  params.abc_probability = 1.0;
  const auto abc = label_counts(synthesize_cloud(params, 0));
  params.abc_probability = 0.0;
  const auto uniform = label_counts(synthesize_cloud(params, 0));
  EXPECT_GT(abc[1], uniform[1]);
}

TEST(Synth, RejectsBadParameters) {
  SynthParams params;
  params.min_points = 10;
  EXPECT_THROW(synthesize_cloud(params, 0), Error);
  params = SynthParams{};
  params.noise_levels.clear();
  EXPECT_THROW(check_synth_params(params), Error);
  params = SynthParams{};
  params.band = 0.0;
  EXPECT_THROW(check_synth_params(params), Error);
  EXPECT_THROW(parse_synth_shape("teapot"), Error);
  EXPECT_EQ(parse_synth_shape("holed_sheet"), SynthShape::holed_sheet);
}

}  // namespace
}  // namespace glint::edges
