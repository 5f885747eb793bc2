// Re-rendering: Ward shading under point lights against the formula, the refined albedo's
// interpolation and smoothing between observation voxels of one segment, the segment's refined
// albedo where no voxel around has one, and MaterialLookup's kept neighbourhoods.
#include "reflectance/material_maps.h"

#include <gtest/gtest.h>

#include <cmath>

#include "core/error.h"
#include "fusion/integrate.h"
#include "reflectance/segment_map.h"

namespace glint::reflectance {
namespace {

TEST(MaterialMaps, ShadingIsEquationSixSummedOverTheLights) {
  render::WardMaterial m;
  m.kd = {0.5f, 0.4f, 0.3f};
  m.ks = {0.1f, 0.1f, 0.1f};
  m.alpha = 0.2f;
  const Eigen::Vector3f p(0, 0, 0), n(0, 0, 1), eye(1, 0, 2);
  std::vector<render::PointLight> lights(2);
  lights[0].position = {0, 0, 2};
  lights[0].intensity = {4, 4, 4};
  lights[1].position = {0, 0, -1};  // below the surface: no contribution
  lights[1].intensity = {9, 9, 9};
  const Eigen::Vector3f wi(0, 0, 1), wo = (eye - p).normalized();
  const Eigen::Vector3f expected = render::ward_brdf(m, n, wi, wo) * 4.0f / 4.0f;  // I/r^2 cos
  EXPECT_TRUE(ward_shading(m.alpha, p, n, eye, lights).radiance(m).isApprox(expected, 1e-6f));
  // Seen from behind, nothing.
  EXPECT_TRUE(ward_shading(m.alpha, p, n, Eigen::Vector3f(1, 0, -2), lights).radiance(m).isZero());
}

// Observation voxels (2 cm) of a wall at z = 1.005 m, inside one layer of them (not on a voxel
// face), all in segment 3 with a refined albedo set by `albedo_at` of their surface point, and
// reliable where `reliable_at` says so (everywhere by default). Or of the surface of any depth
// image, seen `frames` times from the origin.
class Wall {
 public:
  // 4-pixel TSDF allocation stride = 3.3 cm < one 4 cm block at 1 m: no block rows missing.
  Wall() : Wall({80, 60, 120.0, 120.0, 39.5, 29.5}, ImageF(80, 60, 1, 1.005f)) {}
  Wall(const Intrinsics& camera, const ImageF& depth, int frames = 1)
      : geometry_(volume_params()), grid_(ObservationGridParams{.voxel_capacity = 1 << 14}) {
    fusion::VisibleBlocks blocks;
    const ImageF colour(depth.width(), depth.height(), 3, 0.2f);
    fusion::integrate(geometry_, depth, colour, camera, Pose::Identity(), blocks);
    for (int frame = 0; frame < frames; ++frame)
      visible_ = grid_.collect(depth, colour, camera, Pose::Identity(), 1.0f, geometry_, frame);
  }
  template <class AlbedoAt, class ReliableAt = bool (*)(const Eigen::Vector3f&)>
  ObservationGrid& with_albedo(
      AlbedoAt albedo_at, ReliableAt reliable_at = [](const Eigen::Vector3f&) { return true; }) {
    for (const VisibleVoxel& seen : visible_) {
      grid_.segment(seen.voxel) = 3;
      grid_.has_refined_kd(seen.voxel) = true;
      grid_.refined_kd(seen.voxel) = albedo_at(grid_.position(seen.voxel));
      grid_.refined_kd_reliable(seen.voxel) = reliable_at(grid_.position(seen.voxel));
      grid_.refined_kd_light_tangent(seen.voxel) = 0;  // lit head-on
    }
    return grid_;
  }
  std::size_t voxels() const { return visible_.size(); }
  ObservationGrid& grid() { return grid_; }
  const std::vector<VisibleVoxel>& visible() const { return visible_; }

 private:
  static fusion::VolumeParams volume_params() {
    fusion::VolumeParams volume;
    volume.block_capacity = 1 << 12;
    return volume;
  }
  fusion::TsdfVolume geometry_;
  ObservationGrid grid_;
  std::vector<VisibleVoxel> visible_;
};

TEST(MaterialMaps, ACornerWhoseAlbedoIsAnOutlierIsLeftOutButATextureEdgeIsNot) {
  Wall wall;
  ASSERT_GT(wall.voxels(), 20u);
  const Eigen::Vector3f p(0.013f, -0.007f, 1.005f);
  // A crease voxel gone white (eq. 7 with too little irradiance) beside p on a 0.4 wall.
  ObservationGrid& grid = wall.with_albedo([&](const Eigen::Vector3f& q) {
    return Eigen::Vector3f::Constant((q - p).head<2>().norm() < 0.012f ? 1.0f : 0.4f);
  });
  Eigen::Vector3f kd;
  ASSERT_TRUE(interpolate_refined_kd(grid, p, 3, kd));
  EXPECT_NEAR(kd.x(), 0.4f, 1e-6f);
  // A texture edge through the cell: half the corners 0.3, half 0.9; both are kept.
  wall.with_albedo([&](const Eigen::Vector3f& q) {
    return Eigen::Vector3f::Constant(q.x() < p.x() ? 0.3f : 0.9f);
  });
  ASSERT_TRUE(interpolate_refined_kd(grid, p, 3, kd));
  EXPECT_GT(kd.x(), 0.35f);
  EXPECT_LT(kd.x(), 0.85f);
}

TEST(MaterialMaps, UnreliableAlbedosGiveWayToTheReliableOnesAround) {
  Wall wall;
  ASSERT_GT(wall.voxels(), 20u);
  const Eigen::Vector3f p(0.013f, -0.007f, 1.005f);
  // A patch under grazing light, its albedo solved far too bright, on a 0.4 wall.
  const auto in_patch = [&](const Eigen::Vector3f& q, float radius) {
    return (q - p).head<2>().norm() < radius;
  };
  const auto bright_patch = [&](float radius) {
    return [&, radius](const Eigen::Vector3f& q) {
      return Eigen::Vector3f::Constant(in_patch(q, radius) ? 0.95f : 0.4f);
    };
  };
  const auto outside_patch = [&](float radius) {
    return [&, radius](const Eigen::Vector3f& q) { return !in_patch(q, radius); };
  };
  Eigen::Vector3f kd;
  // Every corner of p's cell in the patch: the reliable voxels one ring further out.
  ObservationGrid& grid = wall.with_albedo(bright_patch(0.025f), outside_patch(0.025f));
  ASSERT_TRUE(interpolate_refined_kd(grid, p, 3, kd));
  EXPECT_NEAR(kd.x(), 0.4f, 1e-6f);
  // Half the corners (too many to be left out as outliers) in a bright strip: the other half.
  wall.with_albedo(
      [](const Eigen::Vector3f& q) {
        return Eigen::Vector3f::Constant(q.x() < 0.02f ? 0.95f : 0.4f);
      },
      [](const Eigen::Vector3f& q) { return q.x() >= 0.02f; });
  ASSERT_TRUE(interpolate_refined_kd(grid, p, 3, kd));
  EXPECT_NEAR(kd.x(), 0.4f, 1e-6f);
  // No reliable voxel near: the unreliable corners after all.
  wall.with_albedo(bright_patch(0.025f), [](const Eigen::Vector3f&) { return false; });
  ASSERT_TRUE(interpolate_refined_kd(grid, p, 3, kd));
  EXPECT_NEAR(kd.x(), 0.95f, 1e-6f);
}

TEST(MaterialMaps, AlbedosSolvedUnderMoreGrazingLightWeighLess) {
  Wall wall;
  ASSERT_GT(wall.voxels(), 20u);
  // A texture edge through p's cell: half its corners 0.3, half 0.9, all reliable.
  const Eigen::Vector3f p(0.013f, -0.007f, 1.005f);
  ObservationGrid& grid = wall.with_albedo([&](const Eigen::Vector3f& q) {
    return Eigen::Vector3f::Constant(q.x() < p.x() ? 0.3f : 0.9f);
  });
  Eigen::Vector3f even, kd;
  ASSERT_TRUE(interpolate_refined_kd(grid, p, 3, even));
  // The bright half solved under light at cosine 0.3 (tangent 3.18, weight 0.099): the dark
  // half's trilinear weights a and the bright half's 1 - a become a and 0.099 (1 - a).
  for (const VisibleVoxel& seen : wall.visible())
    if (grid.position(seen.voxel).x() >= p.x())
      grid.refined_kd_light_tangent(seen.voxel) = std::sqrt(1 - 0.09f) / 0.3f;
  ASSERT_TRUE(interpolate_refined_kd(grid, p, 3, kd));
  const float dark = (0.9f - even.x()) / 0.6f;  // a
  const float weight = 0.09f / 0.91f;
  EXPECT_NEAR(kd.x(), (0.3f * dark + 0.9f * weight * (1 - dark)) / (dark + weight * (1 - dark)),
              1e-5f);
  EXPECT_LT(kd.x(), even.x() - 0.05f);
  // The smoothing weighs them alike (the same edge, no range limit).
  ASSERT_TRUE(interpolate_refined_kd(grid, p, 3, kd, true, {.smoothing = 1e6f}));
  EXPECT_LT(kd.x(), 0.3f + 0.6f * 0.25f);
}

TEST(MaterialMaps, RefinedAlbedoInterpolatesWithinTheSegmentOnly) {
  Wall wall;
  ASSERT_GT(wall.voxels(), 20u);
  // A ramp in x: linear, so trilinear interpolation reproduces it between voxel centres.
  ObservationGrid& grid = wall.with_albedo(
      [](const Eigen::Vector3f& q) { return Eigen::Vector3f::Constant(0.5f + q.x()); });
  // Centre of the wall, between voxel centres.
  const Eigen::Vector3f p(0.013f, -0.007f, 1.005f);
  Eigen::Vector3f kd;
  ASSERT_TRUE(interpolate_refined_kd(grid, p, 3, kd));
  EXPECT_NEAR(kd.x(), 0.5f + p.x(), 5e-3f);
  EXPECT_FALSE(interpolate_refined_kd(grid, p, 4, kd)) << "another segment's voxels are not used";
}

TEST(MaterialMaps, SmoothingAveragesTheScatterOfUniformAlbedosButKeepsATextureEdge) {
  Wall wall;
  ASSERT_GT(wall.voxels(), 20u);
  // A uniform 0.4 wall whose voxels scatter by up to +-5 % (a fixed pseudo-random pattern),
  // as eq. (7) albedos do.
  ObservationGrid& grid = wall.with_albedo([](const Eigen::Vector3f& q) {
    return Eigen::Vector3f::Constant(0.4f *
                                     (1 + 0.05f * std::sin(1234.5f * q.x() + 987.6f * q.y())));
  });
  double trilinear_error = 0, smoothed_error = 0;
  int points = 0;
  for (float x = -0.1f; x <= 0.1f; x += 0.0073f)
    for (float y = -0.08f; y <= 0.08f; y += 0.0091f) {
      const Eigen::Vector3f p(x, y, 1.005f);
      Eigen::Vector3f trilinear, smoothed;
      ASSERT_TRUE(interpolate_refined_kd(grid, p, 3, trilinear));
      ASSERT_TRUE(interpolate_refined_kd(grid, p, 3, smoothed, true, {.smoothing = 0.2f}));
      trilinear_error += std::abs(trilinear.x() - 0.4f);
      smoothed_error += std::abs(smoothed.x() - 0.4f);
      ++points;
    }
  ASSERT_GT(points, 400);
  EXPECT_GT(trilinear_error / points, 0.004);
  // In the wall's plane the wide tent weighs 16 voxels, the trilinear one 4 (fewer near a
  // voxel centre): independent scatter shrinks to about 0.6-0.8 of trilinear's.
  EXPECT_LT(smoothed_error, 0.85 * trilinear_error);

  // A texture edge at x = 0 between 0.3 and 0.9: a point on the dark side whose cell lies on it
  // keeps 0.3, though the wide tent reaches the bright voxels beyond the edge ...
  wall.with_albedo(
      [](const Eigen::Vector3f& q) { return Eigen::Vector3f::Constant(q.x() < 0 ? 0.3f : 0.9f); });
  const Eigen::Vector3f dark(-0.015f, -0.007f, 1.005f);
  Eigen::Vector3f kd;
  ASSERT_TRUE(interpolate_refined_kd(grid, dark, 3, kd, true, {.smoothing = 0.2f}));
  EXPECT_NEAR(kd.x(), 0.3f, 1e-4f);
  // ... which a smoothing without a range limit would blend in.
  ASSERT_TRUE(interpolate_refined_kd(grid, dark, 3, kd, true, {.smoothing = 1e6f}));
  EXPECT_GT(kd.x(), 0.35f);
}

// The wall's voxels as segment 3, with a material from the HemiCNN (zero weights: some
// material, not the tests' concern), lit from the camera.
struct WallMaterial {
  explicit WallMaterial(Wall& wall) : estimator(network, params()) {
    segments.update(wall.grid(), wall.visible(), Image<std::int32_t>(80, 60, 1, 3), true);
    lights[0].position = {0, 0, 0};
    estimator.update(wall.grid(), segments, segments.frame_segments(), lights, 0);
  }
  static SpecularParams params() {
    SpecularParams params;
    params.min_observations = 1;
    params.fit_lobe = false;
    return params;
  }
  SegmentMap segments;
  const HemiCnn network;
  SpecularEstimator estimator;
  std::vector<render::PointLight> lights{1};
};

TEST(MaterialMaps, SegmentsRefinedAlbedoStandsAloneOrAsOneMoreVoxelAndKeptLookupsAgree) {
  Wall wall;
  ObservationGrid& grid = wall.grid();
  WallMaterial wall_material(wall);
  SpecularEstimator& estimator = wall_material.estimator;
  ASSERT_NE(estimator.material(3), nullptr);
  EXPECT_FALSE(estimator.material(3)->kd_refined);

  // Fused with the clamped running mean; a segment without a material ignores it.
  estimator.fuse_refined_albedo(3, {0.4f, 0.3f, 0.2f});
  estimator.fuse_refined_albedo(3, {0.6f, 0.5f, 0.4f});
  estimator.fuse_refined_albedo(7, {1.0f, 1.0f, 1.0f});
  EXPECT_EQ(estimator.material(7), nullptr);
  ASSERT_TRUE(estimator.material(3)->kd_refined);
  const Eigen::Vector3f segment_kd(0.5f, 0.4f, 0.3f);
  EXPECT_TRUE(estimator.material(3)->kd_refined->isApprox(segment_kd, 1e-6f));

  // No voxel has a refined albedo: the segment's, beside the network's unrefined one.
  const Eigen::Vector3f p(0.013f, -0.007f, 1.005f);
  PointMaterial material;
  ASSERT_TRUE(MaterialLookup(grid, estimator)(p, material));
  EXPECT_EQ(material.segment, 3);
  EXPECT_TRUE(material.refined.kd.isApprox(segment_kd, 1e-6f));
  EXPECT_TRUE(material.fused.kd.isApprox(estimator.material(3)->ward.kd));
  // Voxels around p with one: theirs.
  wall.with_albedo([](const Eigen::Vector3f&) { return Eigen::Vector3f::Constant(0.7f); });
  ASSERT_TRUE(MaterialLookup(grid, estimator)(p, material));
  EXPECT_TRUE(material.refined.kd.isApprox(Eigen::Vector3f::Constant(0.7f), 1e-6f));
  // Only unreliable ones (grazing light) anywhere: the segment's again.
  wall.with_albedo([](const Eigen::Vector3f&) { return Eigen::Vector3f::Constant(0.95f); },
                   [](const Eigen::Vector3f&) { return false; });
  ASSERT_TRUE(MaterialLookup(grid, estimator)(p, material));
  EXPECT_TRUE(material.refined.kd.isApprox(segment_kd, 1e-6f));

  // The segment's albedo as one more voxel of weight 0.04, without a range limit (contrast
  // 1e6): beside voxels lit head-on (weight 1, wide tents summing to s) it barely counts,
  // (0.7 s + 0.04 kd) / (s + 0.04) ...
  wall.with_albedo([](const Eigen::Vector3f&) { return Eigen::Vector3f::Constant(0.7f); });
  const AlbedoBlend unlimited{.smoothing = 1e6f, .segment_weight = 0.04f};
  ASSERT_TRUE(MaterialLookup(grid, estimator, unlimited)(p, material));
  const float head_on = material.refined.kd.x();
  EXPECT_LT(head_on, 0.7f);
  EXPECT_GT(head_on, 0.68f);
  // ... which gives s; beside voxels under grazing light (tangent 10, weight 0.01) it dominates.
  const float s = 0.04f * (head_on - segment_kd.x()) / (0.7f - head_on);
  const auto grazing = [&] {
    for (const VisibleVoxel& seen : wall.visible()) grid.refined_kd_light_tangent(seen.voxel) = 10;
  };
  grazing();
  ASSERT_TRUE(MaterialLookup(grid, estimator, unlimited)(p, material));
  EXPECT_NEAR(material.refined.kd.x(), (0.7f * 0.01f * s + 0.04f * 0.5f) / (0.01f * s + 0.04f),
              1e-4f);
  EXPECT_LT(material.refined.kd.x(), 0.6f);
  // Within a range limit (contrast 0.2) a segment albedo far from the voxels' (0.5 against
  // 0.95) counts less.
  wall.with_albedo([](const Eigen::Vector3f&) { return Eigen::Vector3f::Constant(0.95f); });
  grazing();
  ASSERT_TRUE(MaterialLookup(grid, estimator, unlimited)(p, material));
  const float mixed = material.refined.kd.x();
  ASSERT_TRUE(
      MaterialLookup(grid, estimator, {.smoothing = 0.2f, .segment_weight = 0.04f})(p, material));
  EXPECT_GT(material.refined.kd.x(), mixed + 0.05f);
  EXPECT_LT(material.refined.kd.x(), 0.95f);
  // Without a segment albedo (unreliable corners in use) there is nothing to add.
  Eigen::Vector3f kd = Eigen::Vector3f::Zero();
  ASSERT_TRUE(interpolate_refined_kd(grid, p, 3, kd, true, unlimited));
  EXPECT_NEAR(kd.x(), 0.95f, 1e-6f);

  // A lookup that keeps the last point's neighbourhood gives what a fresh one gives, point by
  // point along a sweep that crosses cells and a strip of voxels relabelled to a segment
  // without a material.
  wall.with_albedo([](const Eigen::Vector3f& q) {
    return Eigen::Vector3f(0.3f + q.x(), 0.4f - q.y(), 0.5f + 0.1f * std::sin(300 * q.x()));
  });
  for (const VisibleVoxel& seen : wall.visible())
    if (std::abs(grid.position(seen.voxel).x() - 0.05f) < 0.015f) grid.segment(seen.voxel) = 5;
  const AlbedoBlend smoothing{.smoothing = 0.2f, .segment_weight = 0.04f};
  MaterialLookup lookup(grid, estimator, smoothing);
  int found = 0, missing = 0;
  for (float x = -0.12f; x <= 0.12f; x += 0.0037f) {
    const Eigen::Vector3f q(x, 0.011f - 0.3f * x, 1.005f);
    PointMaterial kept, fresh;
    const bool with_material = lookup(q, kept);
    ASSERT_EQ(with_material, MaterialLookup(grid, estimator, smoothing)(q, fresh)) << x;
    EXPECT_EQ(kept.segment, fresh.segment) << x;
    if (!with_material) {
      ++missing;
      continue;
    }
    ++found;
    EXPECT_EQ(kept.refined.kd, fresh.refined.kd) << x;
  }
  EXPECT_GT(found, 40);
  EXPECT_GT(missing, 3);
}

// Voxels whose observations lack three quarters of the direct light (a shadow cast by a part of
// the scene the camera never saw): the re-rendering's direct light is a quarter there, its
// indirect light whole, and whole again away from them.
TEST(MaterialMaps, AShadowTheGeometryCannotCastDimsTheDirectLightWhereItWasObserved) {
  Wall wall;
  ObservationGrid& grid = wall.grid();
  WallMaterial wall_material(wall);
  const Eigen::Vector3f p(0.013f, -0.007f, 1.005f);
  const auto in_shadow = [&](const Eigen::Vector3f& q) { return (q - p).head<2>().norm() < 0.05f; };
  wall.with_albedo([](const Eigen::Vector3f&) { return Eigen::Vector3f::Constant(0.4f); });
  for (const VisibleVoxel& seen : wall.visible())
    grid.light_shortfall(seen.voxel) = in_shadow(grid.position(seen.voxel)) ? 0.75f : 0.0f;
  MaterialLookup lookup(grid, wall_material.estimator);
  PointMaterial material;
  ASSERT_TRUE(lookup(p, material));
  EXPECT_NEAR(material.direct_share, 0.25f, 1e-6f);
  ASSERT_TRUE(lookup(Eigen::Vector3f(0.1f, 0.05f, 1.005f), material));
  EXPECT_NEAR(material.direct_share, 1.0f, 1e-6f);
  // Halfway between a shadowed and a lit voxel centre: half the shortfall.
  Eigen::Vector3f edge = p;
  for (const VisibleVoxel& seen : wall.visible()) {
    const Eigen::Vector3f& q = grid.position(seen.voxel);
    if (in_shadow(q) && !in_shadow(q + Eigen::Vector3f(0.02f, 0, 0)) && std::abs(q.y()) < 0.02f)
      edge = grid.voxel_centre(grid.voxel_coordinates(seen.voxel)) + Eigen::Vector3f(0.01f, 0, 0);
  }
  edge.z() = 1.005f;
  ASSERT_TRUE(lookup(edge, material));
  EXPECT_NEAR(material.direct_share, 1 - 0.75f / 2, 1e-5f);

  std::vector<render::PointLight> lights(1);
  lights[0].position = {0.3f, 0.2f, 0};
  lights[0].intensity = {2, 2, 2};
  const Eigen::Vector3f n(0, 0, -1), eye(0, 0, 0);
  const float alpha = 0.2f;
  PointLighting lighting{.indirect = Eigen::Vector3f(0.1f, 0.2f, 0.3f)};
  const WardShading whole = ward_shading(alpha, p, n, eye, lights, lighting);
  lighting.direct_share = 0.25f;
  const WardShading dimmed = ward_shading(alpha, p, n, eye, lights, lighting);
  EXPECT_TRUE((dimmed.diffuse - lighting.indirect)
                  .isApprox(0.25f * (whole.diffuse - lighting.indirect), 1e-6f));
  EXPECT_TRUE(dimmed.specular.isApprox(0.25f * whole.specular, 1e-6f));
  // Indirect light the lobe mirrors (an even sky of that radiance) adds ks times it.
  render::WardMaterial m;
  m.kd = {0.5f, 0.4f, 0.3f};
  m.ks = {0.1f, 0.2f, 0.3f};
  m.alpha = alpha;
  lighting.indirect_radiance = lighting.indirect / float(M_PI);
  const WardShading glossy = ward_shading(alpha, p, n, eye, lights, lighting);
  const float lobe_albedo = render::ward_lobe_albedo(n.dot((eye - p).normalized()), alpha);
  EXPECT_TRUE((glossy.radiance(m) - dimmed.radiance(m))
                  .isApprox(lobe_albedo * m.ks.cwiseProduct(lighting.indirect_radiance), 1e-5f));
}

TEST(MaterialMaps, RenderingIntoUsedMapsGivesWhatFreshMapsGive) {
  Wall wall;
  WallMaterial wall_material(wall);
  ASSERT_NE(wall_material.estimator.material(3), nullptr);
  wall.with_albedo(
      [](const Eigen::Vector3f& q) { return Eigen::Vector3f(0.3f + q.x(), 0.4f, 0.5f); });
  // The wall seen by the Wall's camera, over the whole image or its left half only.
  const Intrinsics camera{80, 60, 120.0, 120.0, 39.5, 29.5};
  const auto view_of = [&](int covered_width) {
    const int width = camera.width, height = camera.height;
    fusion::SurfaceView view{ImageF(width, height, 1), ImageF(width, height, 3, NAN),
                             ImageF(width, height, 3, NAN), ImageF()};
    for (int y = 0; y < height; ++y)
      for (int x = 0; x < covered_width; ++x) {
        const float z = 1.005f;
        const Eigen::Vector3f p(float((x - camera.cx) / camera.fx) * z,
                                float((y - camera.cy) / camera.fy) * z, z);
        view.depth_m.at(x, y, 0) = z;
        for (int c = 0; c < 3; ++c) {
          view.points_m.at(x, y, c) = p[c];
          view.normals.at(x, y, c) = c == 2 ? -1.0f : 0.0f;
        }
      }
    return view;
  };
  const auto render = [&](const fusion::SurfaceView& view, MaterialMaps& maps) {
    render_material_maps(view, Pose::Identity(), wall.grid(), wall_material.estimator,
                         wall_material.lights, 1.0f, {.smoothing = 0.2f}, maps);
  };
  MaterialMaps used, fresh;
  render(view_of(80), used);
  ASSERT_EQ(used.covered.at(70, 30, 0), 1.0f);
  render(view_of(40), used);
  render(view_of(40), fresh);
  EXPECT_EQ(used.covered.values(), fresh.covered.values());
  EXPECT_EQ(used.segment.values(), fresh.segment.values());
  EXPECT_EQ(used.kd_refined.values(), fresh.kd_refined.values());
  EXPECT_EQ(used.rgb_refined.values(), fresh.rgb_refined.values());
  EXPECT_EQ(used.alpha.values(), fresh.alpha.values());
  EXPECT_EQ(used.covered.at(70, 30, 0), 0.0f) << "the half the second view misses is cleared";
  EXPECT_EQ(used.covered.at(20, 30, 0), 1.0f);
}

// A concave right-angled corner seen from in front, as a room's: two faces meeting along
// y = 7 mm, z = 1.01 m, each at 45 degrees to the camera's axis (z = 1.01 - |y - 7 mm|), and the
// observation voxels labelled 3 where their surface point lies above the corner, 5 below. The
// voxels along the corner hold both faces and one label: the points of the other face in them
// take their own face's label; points away from the corner keep their voxel's.
TEST(MaterialMaps, PointsOfTwoSurfacesInOneVoxelTakeTheLabelOfTheirOwn) {
  constexpr float kCornerY = 0.007f, kCornerZ = 1.01f;
  const Intrinsics camera{160, 120, 240.0, 240.0, 79.5, 59.5};
  ImageF depth(160, 120, 1);
  for (int y = 0; y < 120; ++y)
    for (int x = 0; x < 160; ++x) {
      const float slope = float((y - camera.cy) / camera.fy);   // y / z along the pixel's ray
      const float below = (kCornerZ + kCornerY) / (1 + slope);  // where y > kCornerY
      const float above = (kCornerZ - kCornerY) / (1 - slope);
      depth.at(x, y, 0) = slope * below >= kCornerY ? below : above;
    }
  Wall corner(camera, depth, 2);
  ObservationGrid& grid = corner.grid();
  ASSERT_GT(corner.voxels(), 100u);
  for (const VisibleVoxel& seen : corner.visible())
    grid.segment(seen.voxel) = grid.position(seen.voxel).y() < kCornerY ? 3 : 5;

  const HemiCnn network;
  SpecularParams params;
  params.fit_lobe = false;
  SpecularEstimator estimator(network, params);
  MaterialLookup lookup(grid, estimator);
  // Points on either face up to 3 cm (along y) from the corner.
  int in_other_voxel = 0, wrong = 0, points = 0;
  for (float along = 0.0005f; along < 0.03f; along += 0.0005f)
    for (float x = -0.05f; x <= 0.05f; x += 0.0037f)
      for (const int face : {3, 5}) {
        const Eigen::Vector3f p(x, kCornerY + (face == 3 ? -along : along), kCornerZ - along);
        const int v = grid.find(p);
        if (v < 0 || grid.segment(v) <= 0) continue;
        PointMaterial material;
        lookup(p, material);  // no material yet: false, with the segment found
        ++points;
        in_other_voxel += grid.segment(v) != face;
        wrong += material.segment != face;
        if (along > 0.02f) {
          EXPECT_EQ(material.segment, face) << p.transpose();
        }
      }
  EXPECT_GT(points, 1000);
  EXPECT_GT(in_other_voxel, 50);
  EXPECT_LT(wrong, in_other_voxel / 2);
}

// (The specular stage's sampling, here for the Wall.) A segment with fewer qualifying voxels
// than the network's 25 branches repeats them, from min_distinct_voxels on.
TEST(SpecularEstimator, SmallSegmentsRepeatTheirVoxelsToFillTheBranches) {
  Wall wall;
  ObservationGrid& grid = wall.grid();
  ASSERT_GT(wall.voxels(), 40u);
  SegmentMap segments;
  segments.update(grid, wall.visible(), Image<std::int32_t>(80, 60, 1, 3), true);
  const HemiCnn network;
  std::vector<render::PointLight> lights(1);
  // Only the first `distinct` voxels keep segment 3 (sampling skips voxels that left it).
  const auto material_with = [&](int distinct, int min_distinct) {
    for (std::size_t k = 0; k < wall.visible().size(); ++k)
      grid.segment(wall.visible()[k].voxel) = int(k) < distinct ? 3 : 4;
    SpecularParams params;
    params.min_observations = 1;
    params.min_distinct_voxels = min_distinct;
    params.fit_lobe = false;
    SpecularEstimator estimator(network, params);
    estimator.update(grid, segments, {3}, lights, 0);
    return estimator.material(3) != nullptr;
  };
  EXPECT_TRUE(material_with(25, 25));
  EXPECT_FALSE(material_with(10, 25)) << "the paper's sampling: 25 distinct voxels";
  EXPECT_TRUE(material_with(10, 8));
  EXPECT_FALSE(material_with(7, 8));
  SpecularParams none;
  none.min_distinct_voxels = 0;
  EXPECT_THROW(SpecularEstimator(network, none), Error);
}

}  // namespace
}  // namespace glint::reflectance
