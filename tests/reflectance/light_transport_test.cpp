// Shadows and interreflections of the reflectance pipeline (reflectance/light_transport.h): a
// voxel behind an occluder gets no light from that light, also where only the true scene holds
// the occluder, and the gathered one-bounce irradiance of a grey floor beside a white wall under
// one point light against a fine quadrature of the wall's radiance, per voxel and pooled over
// its neighbours.
#include "reflectance/light_transport.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <memory>
#include <span>
#include <vector>

#include "core/error.h"
#include "fusion/block_occupancy.h"
#include "fusion/fusion_test_support.h"
#include "render/embree_scene.h"
#include "render/trajectories.h"

namespace glint::reflectance {
namespace {

// An axis-aligned box: its signed distance and where a ray enters it.
struct Box {
  Eigen::Vector3d low, high;
  double sdf(const Eigen::Vector3d& p) const {
    const Eigen::Vector3d d = (low - p).cwiseMax(p - high);
    return d.cwiseMax(0.0).norm() + std::min(d.maxCoeff(), 0.0);
  }
  // The entry t (> 0) of origin + t * ray and the outward normal of the face entered; false
  // where the ray misses it or starts inside.
  bool enter(const Eigen::Vector3d& origin, const Eigen::Vector3d& ray, double& t,
             Eigen::Vector3d& normal) const {
    double t_in = 0, t_out = std::numeric_limits<double>::infinity();
    int axis_in = -1;
    for (int axis = 0; axis < 3; ++axis) {
      if (ray[axis] == 0) {
        if (origin[axis] < low[axis] || origin[axis] > high[axis]) return false;
        continue;
      }
      double t0 = (low[axis] - origin[axis]) / ray[axis];
      double t1 = (high[axis] - origin[axis]) / ray[axis];
      if (t0 > t1) std::swap(t0, t1);
      if (t0 > t_in) t_in = t0, axis_in = axis;
      t_out = std::min(t_out, t1);
    }
    if (axis_in < 0 || t_in > t_out) return false;
    t = t_in;
    normal = Eigen::Vector3d::Zero();
    normal[axis_in] = ray[axis_in] > 0 ? -1 : 1;
    return true;
  }
};

// A scene of boxes: its TSDF (exact, 5 mm voxels) and an observation grid (2 cm) filled from
// views of it, whose pixels show radiance(point, outward normal).
class BoxScene {
 public:
  template <class Radiance>
  BoxScene(std::vector<Box> boxes, Radiance radiance)
      : boxes_(std::move(boxes)),
        radiance_(radiance),
        geometry_(volume_params()),
        grid_(ObservationGridParams{.voxel_capacity = 1 << 16, .allocation_stride_px = 1}) {
    fusion::test::fill_analytic(
        geometry_,
        [&](const Eigen::Vector3d& p) {
          double d = std::numeric_limits<double>::infinity();
          for (const Box& box : boxes_) d = std::min(d, box.sdf(p));
          return d;
        },
        1.2, 0.02);
  }

  // Renders the view (depth and radiance) and collects it as frame `frame`; the grid's
  // visible() are then its voxels.
  void see(const Pose& camera_to_world, const Intrinsics& camera, int frame) {
    ImageF depth(camera.width, camera.height, 1), colour(camera.width, camera.height, 3);
    const Eigen::Matrix3d rotation = camera_to_world.linear();
    const Eigen::Vector3d eye = camera_to_world.translation();
    for (int y = 0; y < camera.height; ++y)
      for (int x = 0; x < camera.width; ++x) {
        const Eigen::Vector3d ray = rotation * camera.ray(x, y);  // camera z = 1: t is depth
        double nearest = std::numeric_limits<double>::infinity(), t;
        Eigen::Vector3d normal, nearest_normal = Eigen::Vector3d::Zero();
        for (const Box& box : boxes_)
          if (box.enter(eye, ray, t, normal) && t < nearest) nearest = t, nearest_normal = normal;
        if (!std::isfinite(nearest)) continue;
        depth.at(x, y, 0) = float(nearest);
        const Eigen::Vector3f seen = radiance_(eye + nearest * ray, nearest_normal);
        for (int c = 0; c < 3; ++c) colour.at(x, y, c) = seen[c];
      }
    grid_.collect(depth, colour, camera, camera_to_world, 1.0f, geometry_, frame);
  }

  const fusion::TsdfVolume& geometry() const { return geometry_; }
  const ObservationGrid& grid() const { return grid_; }
  // Gives each surface voxel the segment segment_of(its position).
  template <class SegmentOf>
  void label(SegmentOf segment_of) {
    for (int v = 0; v < int(grid_.voxel_count()); ++v)
      if (grid_.has_surface(v)) grid_.segment(v) = segment_of(grid_.position(v));
  }

 private:
  static fusion::VolumeParams volume_params() {
    fusion::VolumeParams volume;
    volume.block_capacity = 1 << 15;
    return volume;
  }
  std::vector<Box> boxes_;
  std::function<Eigen::Vector3f(const Eigen::Vector3d&, const Eigen::Vector3d&)> radiance_;
  fusion::TsdfVolume geometry_;
  ObservationGrid grid_;
};

const Intrinsics kWideCamera{320, 240, 200.0, 200.0, 159.5, 119.5};

render::PointLight light_at(const Eigen::Vector3d& position) {
  render::PointLight light;
  light.position = position;
  light.intensity = {1, 1, 1};
  return light;
}

// Light 0 of a plate's shadow on the wall's face z = 1 (as the first test sets them up), as the
// last view saw the wall: no light within |x|, |y| < 0.18, light beyond 0.26 (no acne on the open
// wall), each part seen; `also(voxel, surface point)` checks more of each wall voxel.
template <class Also>
void expect_plate_shadow(const BoxScene& scene, const LightTransport& transport, Also also) {
  int shadowed = 0, lit = 0;
  for (const VisibleVoxel& seen : scene.grid().visible()) {
    const int v = seen.voxel;
    if (!scene.grid().has_surface(v)) continue;
    const Eigen::Vector3f p = scene.grid().position(v);
    if (p.z() < 0.99f) continue;  // the plate's
    const float extent = std::max(std::abs(p.x()), std::abs(p.y()));
    if (extent < 0.18f) {
      EXPECT_FALSE(transport.lighting(v).reaches(0)) << p.transpose();
      ++shadowed;
    } else if (extent > 0.26f) {
      EXPECT_TRUE(transport.lighting(v).reaches(0)) << p.transpose();
      ++lit;
    }
    also(v, p);
  }
  EXPECT_GT(shadowed, 100);
  EXPECT_GT(lit, 50);
}

TEST(LightTransport, AVoxelBehindAnOccluderGetsNoLightFromThatLight) {
  // A wall at z = 1 facing -z; a 20 cm plate at z 0.6-0.65 in front of its centre. Light 0 at
  // z 0.3 straight in front: the plate's shadow on the wall spans |x|, |y| < 0.2-0.23. Light 1
  // far to the side lights the wall's centre past the plate. The camera sees the wall's centre
  // past the plate's edge.
  const Box wall{{-1, -1, 1}, {1, 1, 1.1}}, plate{{-0.1, -0.1, 0.6}, {0.1, 0.1, 0.65}};
  BoxScene scene({wall, plate}, [](const Eigen::Vector3d&, const Eigen::Vector3d&) {
    return Eigen::Vector3f(0.3f, 0.3f, 0.3f);
  });
  scene.see(render::look_at({0.8, 0, 0.2}, {0, 0, 1}), kWideCamera, 0);
  const std::vector<render::PointLight> lights{light_at({0, 0, 0.3}), light_at({1.2, 0, 0.3})};
  LightTransport transport({.shadows = true}, scene.grid().voxel_pool_size());
  const fusion::BlockOccupancy occupancy(scene.geometry());
  transport.update_shadows(scene.grid(), scene.geometry(), occupancy, lights, 0);
  expect_plate_shadow(scene, transport, [&](int v, const Eigen::Vector3f& p) {
    if (std::abs(p.x()) < 0.15f) {
      EXPECT_TRUE(transport.lighting(v).reaches(1)) << p.transpose();
    }
    EXPECT_TRUE(transport.lighting(v).indirect.isZero());  // switched off
  });

  // Switched off, every light reaches every voxel.
  LightTransport off({.shadows = false, .indirect = false}, scene.grid().voxel_pool_size());
  off.update_shadows(scene.grid(), scene.geometry(), occupancy, lights, 0);
  EXPECT_EQ(off.lighting(scene.grid().visible().front().voxel).lit, kAllLights);

  // A point on the wall's open part lit by both, and the shadowed centre, queried directly.
  fusion::RayQueue queue(scene.geometry(), &occupancy);
  const Eigen::Vector3f facing(0, 0, -1);
  EXPECT_EQ(shadow_mask(queue, scene.geometry(), lights, {0.5f, 0.5f, 1.0f}, facing, 0.01f),
            kAllLights);
  EXPECT_EQ(shadow_mask(queue, scene.geometry(), lights, {0, 0, 1}, facing, 0.01f),
            kAllLights & ~LightMask{1});
}

TEST(LightTransport, WithTheTrueSceneAnOccluderTheFusedGeometryLacksStillCastsItsShadow) {
  // The wall and light 0 of the test above; the plate exists only in the true scene (the camera
  // never saw it), so shadow rays through the fused wall alone find every light.
  const Box wall{{-1, -1, 1}, {1, 1, 1.1}};
  BoxScene scene({wall}, [](const Eigen::Vector3d&, const Eigen::Vector3d&) {
    return Eigen::Vector3f(0.3f, 0.3f, 0.3f);
  });
  scene.see(render::look_at({0, 0, 0.1}, {0, 0, 1}), kWideCamera, 0);
  const std::vector<render::PointLight> lights{light_at({0, 0, 0.3})};
  render::Scene truth;
  for (const auto& [centre, size] :
       {std::pair{Eigen::Vector3d(0, 0, 1.05), Eigen::Vector3d(2, 2, 0.1)},
        std::pair{Eigen::Vector3d(0, 0, 0.625), Eigen::Vector3d(0.2, 0.2, 0.05)}}) {
    render::Object box;
    box.size = size;
    box.transform.translation() = centre;
    truth.objects.push_back(box);
  }
  LightTransport fused({.shadows = true}, scene.grid().voxel_pool_size());
  LightTransport oracle({.shadows = true}, scene.grid().voxel_pool_size());
  oracle.use_true_scene(std::make_shared<const render::EmbreeScene>(truth));
  const fusion::BlockOccupancy occupancy(scene.geometry());
  fused.update_shadows(scene.grid(), scene.geometry(), occupancy, lights, 0);
  oracle.update_shadows(scene.grid(), scene.geometry(), occupancy, lights, 0);
  expect_plate_shadow(scene, oracle, [&](int v, const Eigen::Vector3f& p) {
    EXPECT_TRUE(fused.lighting(v).reaches(0)) << p.transpose();
  });

  // A re-rendering's pixels ask the same of the true scene.
  PointLightingQuery query(oracle, scene.grid(), scene.geometry(), occupancy, lights);
  const Eigen::Vector3f facing(0, 0, -1);
  const Eigen::Vector3f eye(0, 0, 0);
  EXPECT_FALSE(query({0, 0, 1}, facing, eye, 0.1f).reaches(0));
  EXPECT_TRUE(query({0.5f, 0.5f, 1}, facing, eye, 0.1f).reaches(0));
}

TEST(LightTransport, ShadowRaysThatPassFusedGeometryAreTheShadowTestsCandidates) {
  // The wall and plate of the first test, both fused. From the wall's centre, light 0's ray
  // crosses the plate's blocks; light 1's passes 50 cm beside it and meets no block.
  const Box wall{{-1, -1, 1}, {1, 1, 1.1}}, plate{{-0.1, -0.1, 0.6}, {0.1, 0.1, 0.65}};
  BoxScene scene({wall, plate}, [](const Eigen::Vector3d&, const Eigen::Vector3d&) {
    return Eigen::Vector3f(0.3f, 0.3f, 0.3f);
  });
  const std::vector<render::PointLight> lights{light_at({0, 0, 0.3}), light_at({1.2, 0, 0.3})};
  const fusion::BlockOccupancy occupancy(scene.geometry());
  // Past the wall's blocks: fill_analytic() allocates those within 8 cm of a surface.
  const LightTransportParams params{
      .shadows = true, .shadow_test = true, .shadow_test_skip_m = 0.2f};
  const Eigen::Vector3f centre(0, 0, 1), facing(0, 0, -1);
  EXPECT_EQ(grazing_lights(occupancy, scene.geometry(), lights, centre, facing, kAllLights, params),
            LightMask{1});
  // Only the lights asked about.
  EXPECT_EQ(
      grazing_lights(occupancy, scene.geometry(), lights, centre, facing, LightMask{2}, params),
      LightMask{0});
  // Off the plate's shadow, no ray meets a block past the wall's.
  EXPECT_EQ(grazing_lights(occupancy, scene.geometry(), lights, {0.7f, 0.7f, 1}, facing, kAllLights,
                           params),
            LightMask{0});
}

// The irradiance at floor point p (normal +y) from a Lambertian wall face x = 0 (normal +x),
// y in [0, 0.6], z in [-0.4, 0.4], of radiance wall(w): E = int L cos_p cos_w / d^2 dA, by the
// midpoint rule on 2 mm cells (at least 15 cm away: below 0.1 % off).
template <class WallRadiance>
double wall_irradiance(const Eigen::Vector3d& p, WallRadiance wall) {
  constexpr double kCell = 0.002;
  double sum = 0;
  for (double y = kCell / 2; y < 0.6; y += kCell)
    for (double z = -0.4 + kCell / 2; z < 0.4; z += kCell) {
      const Eigen::Vector3d w(0, y, z), d = w - p;
      const double d2 = d.squaredNorm();
      const double cos_p = d.y() / std::sqrt(d2), cos_w = -d.x() / std::sqrt(d2);
      if (cos_p > 0 && cos_w > 0) sum += wall(w) * cos_p * cos_w / d2;
    }
  return sum * kCell * kCell;
}

// A white wall (x = 0) standing on a grey floor (y = 0) under one point light; both Lambertian,
// so the wall sends L = kd / pi * I cos / r^2 every way: the observed radiance the floor's voxels
// gather. The scene is seen once, from a camera that sees the whole wall face, then in a narrow
// view of the floor 11-49 cm from the wall: its voxels are the ones gathered for.
class WallBesideFloor {
 public:
  WallBesideFloor()
      : light_(light_at({0.5, 0.8, 0.0})),
        scene_({Box{{-0.2, -0.2, -0.4}, {0, 0.6, 0.4}}, Box{{-0.2, -0.2, -0.4}, {0.8, 0, 0.4}}},
               [this](const Eigen::Vector3d& point, const Eigen::Vector3d& normal) {
                 const double kd = normal.x() > 0.5 ? 0.9 : normal.y() > 0.5 ? 0.3 : 0;
                 return Eigen::Vector3f::Constant(float(kd / M_PI * direct(point, normal)));
               }) {
    scene_.see(render::look_at({2.0, 1.0, 0.0}, {0.3, 0.2, 0.0}), kWideCamera, 0);
    // From high up: the floor's mirror directions from here pass over the wall.
    scene_.see(render::look_at({1.2, 2.5, 0.3}, {0.3, 0.0, 0.0}), kWideCamera, 1);
    scene_.see(render::look_at({0.9, 0.6, 0.0}, {0.3, 0.0, 0.0}),
               {64, 48, 200.0, 200.0, 31.5, 23.5}, 2);
  }
  // The gather's estimates after one frame with `params`.
  LightTransport gather(const LightTransportParams& params) const {
    LightTransport transport(params, scene_.grid().voxel_pool_size());
    const fusion::BlockOccupancy occupancy(scene_.geometry());
    transport.update_indirect(scene_.grid(), scene_.geometry(), occupancy, {light_}, 0);
    return transport;
  }
  // The lobe rays of the floor voxels' observations (LightTransportParams::indirect_mirror) for a
  // lobe of width `alpha`.
  LightTransport mirror(LightTransportParams params, float alpha) const {
    params.indirect_specular = IndirectSpecular::mirror;
    LightTransport transport(params, scene_.grid().voxel_pool_size(),
                             scene_.grid().params().observations_per_voxel);
    const fusion::BlockOccupancy occupancy(scene_.geometry());
    transport.update_mirrors(scene_.grid(), scene_.geometry(), occupancy, {light_}, floor_voxels(),
                             [&](int) { return alpha; });
    return transport;
  }
  const ObservationGrid& grid() const { return scene_.grid(); }
  BoxScene& boxes() { return scene_; }
  const render::PointLight& light() const { return light_; }
  // The wall's radiance at point w of its face.
  double wall_radiance(const Eigen::Vector3d& w) const {
    return 0.9 / M_PI * direct(w, Eigen::Vector3d::UnitX());
  }
  // The floor voxels 15-45 cm from the wall, within 5 cm of its middle.
  std::vector<int> floor_voxels() const {
    std::vector<int> voxels;
    for (const VisibleVoxel& seen : scene_.grid().visible()) {
      const Eigen::Vector3f p = scene_.grid().position(seen.voxel);
      if (scene_.grid().has_surface(seen.voxel) && std::abs(p.y()) <= 0.005f && p.x() >= 0.15f &&
          p.x() <= 0.45f && std::abs(p.z()) <= 0.05f)
        voxels.push_back(seen.voxel);
    }
    return voxels;
  }
  const Eigen::Vector3f& position(int v) const { return scene_.grid().position(v); }
  int any_voxel() const { return scene_.grid().visible().front().voxel; }
  // The wall's irradiance at floor point p, by quadrature.
  double expected(const Eigen::Vector3f& p) const {
    return wall_irradiance(p.cast<double>(),
                           [&](const Eigen::Vector3d& w) { return wall_radiance(w); });
  }

 private:
  double direct(const Eigen::Vector3d& point, const Eigen::Vector3d& normal) const {
    const Eigen::Vector3d to_light = light_.position - point;
    return std::max(0.0, normal.dot(to_light.normalized())) / to_light.squaredNorm();
  }
  render::PointLight light_;
  BoxScene scene_;
};

TEST(LightTransport, GatheredIndirectIrradianceOfAFloorBesideAWhiteWallMatchesAQuadrature) {
  const WallBesideFloor scene;
  LightTransportParams params{.shadows = false, .indirect = true, .indirect_rays = 4096};
  params.indirect_scaled = false;  // the gather as it is
  params.indirect_rays_per_frame = params.indirect_rays;
  params.indirect_every_frames = 1;
  // Each voxel's own estimate, and the pooled one (the default), which averages it with its
  // neighbours' on the floor: the irradiance is close to linear over 2 cm, so the pool's mean
  // stays on the voxel's.
  for (const bool pooling : {false, true}) {
    params.indirect_pooling = pooling;
    const LightTransport transport = scene.gather(params);
    // Tolerance: the estimate's relative standard error with 4096 cosine-weighted rays, of which
    // about a third meet the wall, is about 2 % (less with the low-discrepancy directions); each
    // hit takes the radiance of the 2 cm voxel it lands in, which differs from the radiance at
    // the hit by up to ~4 % where the wall's irradiance varies fastest; the rays start 1 cm above
    // the floor. 5 % per voxel, 2 % on their mean.
    double sum_ratio = 0;
    const std::vector<int> voxels = scene.floor_voxels();
    ASSERT_GT(voxels.size(), 20u);
    for (const int v : voxels) {
      const Eigen::Vector3f p = scene.position(v);
      ASSERT_EQ(transport.indirect_rays(v), params.indirect_rays) << p.transpose();
      const double expected = scene.expected(p);
      const Eigen::Vector3f gathered = transport.lighting(v).indirect;
      EXPECT_NEAR(gathered.x(), expected, 0.05 * expected) << p.transpose() << " " << pooling;
      EXPECT_FLOAT_EQ(gathered.x(), gathered.z());  // grey light on grey surfaces
      sum_ratio += gathered.x() / expected;
    }
    EXPECT_NEAR(sum_ratio / double(voxels.size()), 1.0, 0.02) << pooling;
  }

  // Off: no indirect light.
  LightTransport off({.shadows = false, .indirect = false}, 16);
  EXPECT_TRUE(off.lighting(scene.any_voxel()).indirect.isZero());
}

// The floor's segment (more voxels) is the largest plane; without its albedo, the wall's face;
// the two as one segment are no plane.
TEST(ContinuedPlane, TheLargestPlanarSegmentWithAnAlbedoIsContinued) {
  WallBesideFloor scene;
  scene.boxes().label([](const Eigen::Vector3f& p) {
    return std::abs(p.y()) < 0.01f ? 1 : std::abs(p.x()) < 0.01f ? 2 : 3;  // 3: the boxes' sides
  });
  const auto albedo_of = [](Eigen::Vector3f floor) {
    return [floor](int segment) { return segment == 1 ? floor : Eigen::Vector3f::Constant(0.9f); };
  };
  const ContinuedPlane floor = largest_plane(scene.grid(), 0.02f, albedo_of({0.3f, 0.3f, 0.3f}));
  EXPECT_GT(floor.normal.y(), 0.999f);
  EXPECT_NEAR(floor.offset, 0.0f, 0.005f);
  EXPECT_FLOAT_EQ(floor.albedo.x(), 0.3f);
  const ContinuedPlane wall =
      largest_plane(scene.grid(), 0.02f, albedo_of(Eigen::Vector3f::Constant(NAN)));
  EXPECT_GT(wall.normal.x(), 0.999f);
  EXPECT_NEAR(wall.offset, 0.0f, 0.005f);
  scene.boxes().label([](const Eigen::Vector3f& p) {
    return std::abs(p.y()) < 0.01f || std::abs(p.x()) < 0.01f ? 1 : 3;
  });
  EXPECT_FALSE(largest_plane(scene.grid(), 0.02f, albedo_of({0.3f, 0.3f, 0.3f})).known());
}

// The wall continued beyond the reconstruction's box: the floor's gather rays that leave the box
// above or beside the wall and meet its plane there bring the wall's model radiance, which is the
// scene's own wall radiance (kd 0.9, Lambertian under the light). What that adds to each floor
// voxel's gathered light matches a quadrature of the wall's plane outside the box (2 cm cells up
// to 10 m: the rays' reach), within 10 % per voxel (a tenth of 4096 rays meet it) and 3 % on
// their mean.
TEST(LightTransport, RaysLeavingTheReconstructionMeetTheContinuedPlaneBeyondIt) {
  WallBesideFloor scene;
  LightTransportParams params{.shadows = false, .indirect = true, .indirect_rays = 4096};
  params.indirect_scaled = false;
  params.indirect_pooling = false;
  params.indirect_rays_per_frame = params.indirect_rays;
  params.indirect_every_frames = 1;
  const fusion::BlockOccupancy occupancy(scene.boxes().geometry());
  Eigen::Vector3i low_block, high_block;
  ASSERT_TRUE(occupancy.bounds(low_block, high_block));
  const double block = scene.boxes().geometry().params().block_size_m();
  const Eigen::Vector3d low = low_block.cast<double>() * block,
                        high = (high_block + Eigen::Vector3i::Ones()).cast<double>() * block;
  const auto gathered = [&](const ContinuedPlane& plane) {
    LightTransport transport(params, scene.grid().voxel_pool_size());
    transport.set_continued_plane(plane);
    transport.update_indirect(scene.grid(), scene.boxes().geometry(), occupancy, {scene.light()},
                              0);
    return transport;
  };
  const LightTransport without = gathered({});
  const LightTransport with =
      gathered({.normal = Eigen::Vector3f::UnitX(), .offset = 0, .albedo = {0.9f, 0.9f, 0.9f}});
  double sum_ratio = 0;
  const std::vector<int> voxels = scene.floor_voxels();
  ASSERT_GT(voxels.size(), 20u);
  for (const int v : voxels) {
    const Eigen::Vector3d p = scene.position(v).cast<double>();
    const Eigen::Vector3d origin = p + params.ray_offset_m * Eigen::Vector3d::UnitY();
    constexpr double kCell = 0.02;
    double expected = 0;
    for (double y = kCell / 2; y < 10; y += kCell)
      for (double z = -10 + kCell / 2; z < 10; z += kCell) {
        const Eigen::Vector3d w(0, y, z), d = w - origin;
        if (y <= high.y() && z >= low.z() && z <= high.z()) continue;  // inside the box
        const double d2 = d.squaredNorm();
        const double cos_p = d.y() / std::sqrt(d2), cos_w = -d.x() / std::sqrt(d2);
        if (cos_p > 0 && cos_w > 0 &&
            d2 <= params.indirect_max_distance_m * params.indirect_max_distance_m)
          expected += scene.wall_radiance(w) * cos_p * cos_w / d2;
      }
    expected *= kCell * kCell;
    const double added = with.lighting(v).indirect.x() - without.lighting(v).indirect.x();
    EXPECT_NEAR(added, expected, 0.1 * expected) << p.transpose();
    sum_ratio += added / expected;
  }
  EXPECT_NEAR(sum_ratio / double(voxels.size()), 1.0, 0.03);
}

TEST(LightTransport, APooledEstimateHasLightBeforeItsVoxelHasEnoughRaysOfItsOwn) {
  // 4 rays per voxel, fewer than the 8 an estimate needs: alone, no voxel counts indirect light
  // yet; pooled with its neighbours on the floor (9 of them at most, the rays of a 2 cm square
  // around it), every one does, and near the quadrature. Tolerance: about 36 rays with a third
  // on the wall scatter by about a fifth per voxel; the mean over the 20+ voxels by 5 %, 10 %
  // with the hit voxels' radiance as above.
  const WallBesideFloor scene;
  LightTransportParams params{.shadows = false, .indirect = true, .indirect_rays_per_frame = 4};
  params.indirect_scaled = false;  // the gather as it is
  params.indirect_every_frames = 1;
  params.indirect_pooling = false;
  const LightTransport alone = scene.gather(params);
  params.indirect_pooling = true;
  const LightTransport pooled = scene.gather(params);
  double sum_ratio = 0;
  const std::vector<int> voxels = scene.floor_voxels();
  ASSERT_GT(voxels.size(), 20u);
  for (const int v : voxels) {
    ASSERT_EQ(alone.indirect_rays(v), 4);
    EXPECT_TRUE(alone.lighting(v).indirect.isZero());
    const float gathered = pooled.lighting(v).indirect.x();
    EXPECT_GT(gathered, 0.0f) << scene.position(v).transpose();
    sum_ratio += gathered / scene.expected(scene.position(v));
  }
  EXPECT_NEAR(sum_ratio / double(voxels.size()), 1.0, 0.1);
}

TEST(LightTransport, TheSceneScaleMultipliesTheGatheredLightOnceItHasEnoughSamples) {
  const WallBesideFloor scene;
  LightTransportParams params{.shadows = false, .indirect = true, .indirect_rays_per_frame = 16};
  params.indirect_every_frames = 1;
  params.indirect_scaled = true;
  LightTransport transport = scene.gather(params);
  const int v = scene.floor_voxels().front();
  const Eigen::Vector3f gathered = transport.gathered(v);
  ASSERT_GT(gathered.x(), 0.0f);
  // No samples yet: the gathered light is not taken (it may be what a rendering lacks).
  EXPECT_FLOAT_EQ(transport.indirect_scale(), 0.0f);
  EXPECT_TRUE(transport.lighting(v).indirect.isZero());
  const std::vector<float> samples(std::size_t(params.indirect_scale_min_samples) - 1, 1.5f);
  transport.add_indirect_scale_samples(samples);
  EXPECT_FLOAT_EQ(transport.indirect_scale(), 0.0f);
  // The median of the samples, from indirect_scale_min_samples on.
  const std::vector<float> more{1.5f, 1.5f, 0.1f};
  transport.add_indirect_scale_samples(more);
  EXPECT_FLOAT_EQ(transport.indirect_scale(), 1.5f);
  EXPECT_TRUE(transport.lighting(v).indirect.isApprox(1.5f * gathered));
  // The latest kIndirectScaleSamples count: a scene whose unlit voxels turn black loses the
  // gathered light; samples beyond the cap are clamped to it.
  const std::vector<float> black(LightTransport::kIndirectScaleSamples, 0.0f);
  transport.add_indirect_scale_samples(black);
  EXPECT_TRUE(transport.lighting(v).indirect.isZero());
  EXPECT_FALSE(transport.indirect_scale_capped());
  const std::vector<float> bright(LightTransport::kIndirectScaleSamples / 2 + 1, 9.0f);
  transport.add_indirect_scale_samples(bright);
  EXPECT_FLOAT_EQ(transport.indirect_scale(), params.indirect_scale_max);
  EXPECT_TRUE(transport.indirect_scale_capped());  // `glint reconstruct` warns of it
  // Unscaled: the gather as it is, whatever the samples.
  params.indirect_scaled = false;
  params.indirect_specular = IndirectSpecular::off;
  LightTransport unscaled = scene.gather(params);
  unscaled.add_indirect_scale_samples(black);
  EXPECT_FLOAT_EQ(unscaled.indirect_scale(), 1.0f);
  unscaled.add_indirect_scale_samples(bright);
  EXPECT_FLOAT_EQ(unscaled.indirect_scale(), 1.0f);
  EXPECT_FALSE(unscaled.indirect_scale_capped());
  EXPECT_TRUE(unscaled.lighting(v).indirect.isApprox(gathered));
  EXPECT_TRUE(unscaled.lighting(v).indirect_radiance.isZero());  // the lobe mirrors none of it
  // Mirrored by the specular lobe as well: as an even sky of radiance E / pi.
  params.indirect_specular = IndirectSpecular::sky;
  const LightTransport glossy = scene.gather(params);
  EXPECT_TRUE(glossy.lighting(v).indirect_radiance.isApprox(gathered / float(M_PI)));
  // Without the gather there is nothing to scale.
  EXPECT_FLOAT_EQ(LightTransport({.indirect = false}, 16).indirect_scale(), 1.0f);
}

TEST(LightTransport, AnObservationsLobeRaysMeetWhatItsMirrorDirectionSees) {
  // A sharp lobe (alpha 0.01, half a degree wide): the floor voxels' observations from the side
  // mirror to the wall, where their rays (from 1 cm above the floor) meet the wall's radiance at
  // the mirror point: the hit takes the colour of one observation of the 2 cm voxel it lands in
  // (or of the one half a voxel back), up to ~2 cm from the hit, and the radiance changes by up
  // to ~6 % per cm (the light is 60 cm away): within 25 % each, 90 % of them within 10 %, and
  // within 3 % on average. Those from high up pass over the wall and meet nothing: dark.
  const WallBesideFloor scene;
  LightTransportParams params{.shadows = false, .indirect = true};
  params.indirect_scaled = false;
  const LightTransport transport = scene.mirror(params, 0.01f);
  std::array<Eigen::Vector3f, kMaxObservationsPerVoxel> mirrored;
  int on_wall = 0, over_wall = 0, close = 0;
  double sum_ratio = 0;
  for (const int v : scene.floor_voxels()) {
    const Eigen::Vector3f p = scene.position(v);
    const Observation* observations = scene.grid().observations(v);
    const std::span<const Eigen::Vector3f> radiance = transport.mirrored(scene.grid(), v, mirrored);
    ASSERT_EQ(int(radiance.size()), scene.grid().observation_count(v));
    for (int k = 0; k < scene.grid().observation_count(v); ++k) {
      const Eigen::Vector3f d = observations[k].direction();
      const Eigen::Vector3f r(-d.x(), d.y(), -d.z());  // the mirror direction about +y
      const Eigen::Vector3f origin = p + params.ray_offset_m * Eigen::Vector3f::UnitY();
      const Eigen::Vector3f hit = origin + origin.x() / d.x() * r;  // on the wall's plane x = 0
      if (hit.y() > 0.03f && hit.y() < 0.57f && std::abs(hit.z()) < 0.37f) {
        const double expected = scene.wall_radiance(hit.cast<double>());
        const double ratio = radiance[std::size_t(k)].x() / expected;
        EXPECT_NEAR(ratio, 1.0, 0.25) << p.transpose() << ", wall at " << hit.transpose();
        sum_ratio += ratio;
        close += std::abs(ratio - 1.0) <= 0.1;
        ++on_wall;
      } else if (hit.y() > 0.63f) {
        EXPECT_TRUE(radiance[std::size_t(k)].isZero()) << p.transpose();
        ++over_wall;
      }
    }
  }
  EXPECT_GT(on_wall, 40);
  EXPECT_NEAR(sum_ratio / on_wall, 1.0, 0.03);
  EXPECT_GE(close, 0.9 * on_wall);
  EXPECT_GT(over_wall, 20);
  // Scaled like the gather, up to 1: before the scene scale has samples (a rendering without
  // bounced light: 0) the lobe mirrors nothing.
  params.indirect_scaled = true;
  const LightTransport unscaled_yet = scene.mirror(params, 0.01f);
  const int v = scene.floor_voxels().front();
  for (const Eigen::Vector3f& radiance : unscaled_yet.mirrored(scene.grid(), v, mirrored))
    EXPECT_TRUE(radiance.isZero());
  // The even sky, or nothing: no lobe rays.
  for (const IndirectSpecular other : {IndirectSpecular::sky, IndirectSpecular::off}) {
    params.indirect_specular = other;
    EXPECT_TRUE(LightTransport(params, 16).mirrored(scene.grid(), v, mirrored).empty());
  }
  EXPECT_EQ(parse_indirect_specular("mirror"), IndirectSpecular::mirror);
  EXPECT_STREQ(indirect_specular_name(IndirectSpecular::sky), "sky");
  EXPECT_THROW(parse_indirect_specular("on"), Error);
}

// A lobe weaker than kMirrorMinKs in every channel casts no rays: the pipeline hands it alpha 0,
// its observations' mirrored radiance stays unknown (NaN), and eq. (7) takes the even sky
// (PointLighting::indirect_radiance) in its place; one channel at the threshold casts them.
TEST(LightTransport, AWeakLobeCastsNoRaysAndMirrorsTheEvenSky) {
  EXPECT_FALSE(casts_lobe_rays(Eigen::Vector3f(0.04f, 0.02f, 0.0499f)));
  EXPECT_TRUE(casts_lobe_rays(Eigen::Vector3f(0.01f, kMirrorMinKs, 0.01f)));
  const WallBesideFloor scene;
  LightTransportParams params{.shadows = false, .indirect = true};
  params.indirect_scaled = false;
  const LightTransport transport = scene.mirror(params, 0.0f);
  std::array<Eigen::Vector3f, kMaxObservationsPerVoxel> mirrored;
  int observations = 0;
  for (const int v : scene.floor_voxels())
    for (const Eigen::Vector3f& radiance : transport.mirrored(scene.grid(), v, mirrored)) {
      EXPECT_TRUE(radiance.array().isNaN().all());
      ++observations;
    }
  EXPECT_GT(observations, 40);
}

// The scaled gather's error at one voxel: the spread of the scale's samples about their median,
// 1.4826 MAD / median (a normal distribution's standard deviation, relative).
TEST(LightTransport, TheGathersErrorIsTheSpreadOfTheScaleSamples) {
  LightTransport transport({.shadows = false, .indirect = true}, 16);
  EXPECT_EQ(transport.indirect_error(), 0.0f);
  std::vector<float> samples(22, 1.0f);  // median 2, absolute deviations 21 x 0 and 43 x 1
  samples.insert(samples.end(), 21, 2.0f);
  samples.insert(samples.end(), 21, 3.0f);
  transport.add_indirect_scale_samples(samples);
  EXPECT_FLOAT_EQ(transport.indirect_scale(), 2.0f);
  EXPECT_FLOAT_EQ(transport.indirect_error(), 1.4826f / 2);
  // Black unlit voxels (no bounced light): the scale is 0 and so is the error.
  transport.add_indirect_scale_samples(
      std::vector<float>(LightTransport::kIndirectScaleSamples, 0.0f));
  EXPECT_EQ(transport.indirect_scale(), 0.0f);
  EXPECT_EQ(transport.indirect_error(), 0.0f);
}

TEST(LightTransport, RaysArePooledOnlyAlongTheSameSurface) {
  const float voxel = 0.02f;
  const Eigen::Vector3f p(0, 0, 0), up = Eigen::Vector3f::UnitY();
  // A floor neighbour, also on a gentle (20 degree) bend.
  EXPECT_TRUE(pools_indirect_rays(p, up, {0.02f, 0.002f, 0}, up, voxel));
  const float bend = 20 * float(M_PI) / 180;
  EXPECT_TRUE(
      pools_indirect_rays(p, up, {0.02f, 0.007f, 0}, {-std::sin(bend), std::cos(bend), 0}, voxel));
  // A wall meeting the floor (a crease): its irradiance is another's.
  EXPECT_FALSE(pools_indirect_rays(p, up, {0.02f, 0.01f, 0}, Eigen::Vector3f::UnitX(), voxel));
  // The far side of a thin board, and a parallel surface 2 cm above (a step).
  EXPECT_FALSE(pools_indirect_rays(p, up, {0.0f, -0.008f, 0}, -up, voxel));
  EXPECT_FALSE(pools_indirect_rays(p, up, {0.02f, 0.02f, 0}, up, voxel));
}

TEST(LightTransport, RejectsBadParameters) {
  EXPECT_THROW(LightTransport({.indirect_rays = 0}, 16), Error);
  EXPECT_THROW(LightTransport({.indirect_rays = 8, .indirect_min_rays = 9}, 16), Error);
  EXPECT_THROW(LightTransport({.ray_offset_m = -0.01f}, 16), Error);
  EXPECT_THROW(LightTransport({.shadow_refresh_frames = 0}, 16), Error);
  EXPECT_THROW(LightTransport({.shadow_test_ratio = 0.9f}, 16), Error);
  EXPECT_THROW(LightTransport({.shadow_test_sigmas = -1}, 16), Error);
  EXPECT_THROW(LightTransport({.shadow_test_sigmas = INFINITY}, 16), Error);
  EXPECT_THROW(LightTransport({.shadow_test_skip_m = -1}, 16), Error);
  EXPECT_THROW(LightTransport({.indirect_scale_min_samples = 0}, 16), Error);
  EXPECT_THROW(LightTransport({.indirect_scale_min_samples = 2000}, 16), Error);
  EXPECT_THROW(LightTransport({.indirect_scale_max = 0}, 16), Error);
}

}  // namespace
}  // namespace glint::reflectance
