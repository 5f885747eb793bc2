// The built-in scenes: ids, physically plausible materials, sizes and cameras as documented in
// render/builtin_scenes.h, and the light-capture sequence that sees the lights. No mesh is
// loaded here, so these tests need no data folder.
#include "render/builtin_scenes.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <set>

#include "core/error.h"
#include "render/renderer.h"
#include "render/sensor.h"

namespace glint::render {
namespace {

BuiltinOptions small_options() {
  BuiltinOptions options;
  options.data_dir = "DATA";
  options.frames = 40;
  return options;
}

bool projects_into(const Intrinsics& camera, const Pose& pose, const Eigen::Vector3d& point) {
  const Eigen::Vector3d in_camera = pose.inverse() * point;
  if (in_camera.z() <= 0) return false;
  const Eigen::Vector2d pixel = camera.project(in_camera);
  return pixel.x() >= 0 && pixel.y() >= 0 && pixel.x() <= camera.width - 1 &&
         pixel.y() <= camera.height - 1;
}

const Object& named(const Scene& scene, const std::string& name) {
  for (const Object& object : scene.objects)
    if (object.name == name) return object;
  throw Error(name, "", "no such object");
}

class EveryBuiltinScene : public testing::TestWithParam<std::string> {};

TEST_P(EveryBuiltinScene, IdsAreUniqueAndMaterialsPlausible) {
  const Scene scene = make_builtin_scene(GetParam(), small_options());
  ASSERT_GE(scene.objects.size(), 4u);
  std::set<int> ids;
  for (const Object& object : scene.objects) {
    EXPECT_GE(object.id, 1) << object.name;
    EXPECT_TRUE(ids.insert(object.id).second) << object.name;
    const WardMaterial& ward = object.material.ward;
    EXPECT_LE((ward.kd + ward.ks).maxCoeff(), 1.0f) << object.name;
    EXPECT_GE(ward.kd.minCoeff(), 0.0f) << object.name;
    EXPECT_GE(ward.ks.minCoeff(), 0.0f) << object.name;
    EXPECT_GT(ward.alpha, 0.0f) << object.name;
    EXPECT_LE(ward.alpha, 0.35f) << object.name;
  }
  EXPECT_GE(scene.lights.size(), 2u);
  EXPECT_EQ(scene.trajectory.size(), 40u);
  EXPECT_EQ(scene.camera.intrinsics.width, 512);
  EXPECT_EQ(scene.camera.intrinsics.height, 424);
}

TEST_P(EveryBuiltinScene, TheCameraSeesTheObjectsAndStandsAboveTheFloor) {
  const Scene scene = make_builtin_scene(GetParam(), small_options());
  for (const Pose& pose : scene.trajectory) {
    EXPECT_GT(pose.translation().y(), 0.5);
    int seen = 0;
    for (const Object& object : scene.objects)
      seen += projects_into(scene.camera.intrinsics, pose, object.transform.translation());
    EXPECT_GE(seen, 3);
  }
}

TEST_P(EveryBuiltinScene, TheLightCaptureSequenceSeesEveryLight) {
  const Scene scene = make_builtin_scene(GetParam(), small_options());
  LightCaptureParams path;
  path.frames = 30;
  const Scene capture = make_light_capture(scene, path);
  EXPECT_EQ(capture.objects.size(), scene.objects.size());
  EXPECT_EQ(capture.lights.size(), scene.lights.size());
  EXPECT_EQ(capture.camera.exposure, kLightCaptureExposure);
  ASSERT_EQ(capture.trajectory.size(), 30u);
  std::vector<int> frames_seeing(scene.lights.size(), 0);
  for (const Pose& pose : capture.trajectory) {
    int seen = 0;
    for (std::size_t l = 0; l < scene.lights.size(); ++l) {
      const bool in_view =
          projects_into(capture.camera.intrinsics, pose, capture.lights[l].position);
      frames_seeing[l] += in_view;
      seen += in_view;
    }
    EXPECT_GE(seen, 1);
  }
  for (int count : frames_seeing) EXPECT_GE(count, 30 / int(scene.lights.size()));
  // At this exposure no proxy clips (its intensity stays measurable) and every proxy reads
  // far above a lit surface.
  for (const PointLight& light : scene.lights) {
    const double proxy_area = M_PI * std::pow(light.proxy_radius_m, 2);
    EXPECT_LT(light.intensity.maxCoeff() / proxy_area * kLightCaptureExposure, 0.8);
    EXPECT_GT(light.intensity.minCoeff() / proxy_area * kLightCaptureExposure, 0.25);
  }
}

INSTANTIATE_TEST_SUITE_P(BuiltinScenes, EveryBuiltinScene,
                         testing::ValuesIn(builtin_scene_names()));

// cubes needs no mesh or texture, so it renders without the data folder.
TEST(BuiltinScenes, RenderedLightCaptureReadsTheProxiesUnclippedAndSurfacesDark) {
  BuiltinOptions options = small_options();
  options.width = 128;
  options.height = 106;
  LightCaptureParams path;
  path.frames = 4;
  const Scene capture = make_light_capture(make_builtin_scene("cubes", options), path);
  const Renderer renderer(capture);
  for (int frame : {0, 3}) {
    const Pose& pose = capture.trajectory[std::size_t(frame)];
    const FrameBuffers buffers = renderer.render(pose, frame);
    const ImageF rgb = expose_colour(buffers.radiance, capture.camera, capture.seed, frame);
    const PointLight& light = capture.lights[std::size_t(frame) * capture.lights.size() / 4];
    const Eigen::Vector2d pixel =
        capture.camera.intrinsics.project(pose.inverse() * light.position);
    const int u = int(std::lround(pixel.x())), v = int(std::lround(pixel.y()));
    const Eigen::Vector3f expected =
        light.intensity / float(M_PI * std::pow(light.proxy_radius_m, 2)) * capture.camera.exposure;
    for (int c = 0; c < 3; ++c)
      EXPECT_NEAR(srgb_to_linear(rgb.at(u, v, c)), expected[c], 0.01f) << "frame " << frame;
    float brightest_surface = 0;  // linear, on the objects and the floor
    for (int y = 0; y < rgb.height(); ++y)
      for (int x = 0; x < rgb.width(); ++x)
        if (buffers.segment.at(x, y, 0) != 0)
          for (int c = 0; c < 3; ++c)
            brightest_surface = std::max(brightest_surface, srgb_to_linear(rgb.at(x, y, c)));
    EXPECT_LT(brightest_surface, 0.02f) << "frame " << frame;
  }
}

TEST(BuiltinScenes, CubesAreFourDecimetreCubesFourMetresAway) {
  const Scene scene = make_builtin_scene("cubes", small_options());
  int cubes = 0;
  for (const Object& object : scene.objects)
    if (object.shape == ShapeKind::box) {
      ++cubes;
      EXPECT_TRUE(object.size.isApprox(Eigen::Vector3d::Constant(0.4))) << object.name;
      EXPECT_NEAR(object.transform.translation().y(), 0.2, 1e-12) << object.name;  // on the floor
    }
  EXPECT_EQ(cubes, 6);
  for (const Pose& pose : scene.trajectory)
    EXPECT_NEAR((pose.translation() - Eigen::Vector3d(0, 0.2, 0)).norm(), 4.0, 0.05);
}

TEST(BuiltinScenes, BunniesAreYellowTealOrangeAndOneAndAHalfMetresHigh) {
  const Scene scene = make_builtin_scene("bunnies", small_options());
  for (const std::string name : {"yellow bunny", "teal bunny", "orange bunny"}) {
    const Object& bunny = named(scene, name);
    EXPECT_EQ(bunny.shape, ShapeKind::mesh);
    EXPECT_EQ(bunny.mesh_path, "DATA/meshes/stanford-bunny.obj");
    EXPECT_DOUBLE_EQ(bunny.size.y(), 1.5);
  }
  const WardMaterial yellow = named(scene, "yellow bunny").material.ward;
  EXPECT_GT(yellow.kd.x(), yellow.kd.z() * 5);  // red and green, little blue
  const WardMaterial teal = named(scene, "teal bunny").material.ward;
  EXPECT_LT(teal.kd.x(), teal.kd.y() / 5);
  const WardMaterial orange = named(scene, "orange bunny").material.ward;
  EXPECT_GT(orange.kd.x(), 2 * orange.kd.y());
  // Distinct specularities, glossy to rough.
  EXPECT_LT(yellow.alpha, teal.alpha);
  EXPECT_LT(teal.alpha, orange.alpha);
  EXPECT_EQ(named(scene, "floor").shape, ShapeKind::plane);
}

TEST(BuiltinScenes, OfficeHasWallsFacingInwardAndATexturedTable) {
  const Scene scene = make_builtin_scene("office", small_options());
  const Eigen::Vector3d room_centre(0, 1.4, 0);
  for (const std::string name : {"back wall", "left wall", "right wall"}) {
    const Object& wall = named(scene, name);
    const Eigen::Vector3d normal = wall.transform.linear() * Eigen::Vector3d::UnitY();
    EXPECT_NEAR(normal.y(), 0, 1e-12) << name;
    EXPECT_GT(normal.dot(room_centre - wall.transform.translation()), 2.9) << name;
  }
  EXPECT_EQ(named(scene, "table").material.kd_texture, "DATA/textures/onyx/albedo.jpg");
  for (const PointLight& light : scene.lights) EXPECT_NEAR(light.position.y(), 2.6, 1e-12);
}

TEST(BuiltinScenes, UnknownNameThrows) {
  EXPECT_THROW(make_builtin_scene("kitchen", small_options()), Error);
}

TEST(SensorIntrinsics, ScalesTheKinectCamera) {
  const Intrinsics full = sensor_intrinsics(512, 424);
  const Intrinsics kinect = kinect_v2_intrinsics();
  EXPECT_DOUBLE_EQ(full.fx, kinect.fx);
  EXPECT_DOUBLE_EQ(full.cx, kinect.cx);
  EXPECT_DOUBLE_EQ(full.cy, kinect.cy);
  const Intrinsics half = sensor_intrinsics(256, 212);
  EXPECT_DOUBLE_EQ(half.fx, kinect.fx / 2);
  EXPECT_DOUBLE_EQ(half.fy, kinect.fy / 2);
  EXPECT_DOUBLE_EQ(half.cx, 127.5);
  EXPECT_DOUBLE_EQ(half.cy, 105.5);
  EXPECT_THROW(sensor_intrinsics(0, 10), Error);
}

}  // namespace
}  // namespace glint::render
