// scene.json: a full round trip, orbit trajectories, relative paths and bad inputs.
#include "render/scene_json.h"

#include <gtest/gtest.h>

#include <fstream>

#include "io/image_io.h"
#include "io/json_report.h"
#include "scene_fixtures.h"
#include "support/error_of.h"

namespace glint::render {
namespace {

const std::string kData = std::string(GLINT_TEST_DATA_DIR) + "/render/";

Scene full_scene(const std::string& texture, const std::string& environment) {
  Scene scene = test::plane_scene();
  scene.objects[0].material.kd_texture = texture;
  scene.objects[0].material.texture_scale_m = 0.5f;
  Object mesh = test::make_object(3, ShapeKind::mesh, {1, 0.8, 1}, {0.5, 0, -0.3});
  mesh.mesh_path = kData + "pyramid.obj";
  mesh.transform.linear() = Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, 2, 3).normalized()).matrix();
  mesh.material.ward = WardMaterial{{0.1f, 0.2f, 0.3f}, {0.3f, 0.2f, 0.1f}, 0.07f};
  scene.objects.push_back(mesh);
  scene.objects.push_back(test::make_object(4, ShapeKind::sphere, {0.2, 0.2, 0.2}, {0, 0.2, 0}));
  scene.environment = Environment{environment, 0.5f, 30.0f, 16};
  scene.camera.exposure = 0.3f;
  scene.camera.sensor_noise = 0.01f;
  scene.camera.depth_noise = true;
  scene.trajectory.push_back(look_at({1, 1, 1}, {0, 0, 0}));
  scene.frames_per_second = 15;
  scene.shadows = false;
  scene.bounces = 3;
  scene.indirect_samples = 17;
  scene.seed = 42;
  return scene;
}

TEST(SceneJson, RoundTripKeepsEveryField) {
  test::TemporaryFolder folder;
  io::write_image(folder.path("albedo.png"), ImageF(4, 4, 3, 0.5f));
  io::write_image(folder.path("sky.exr"), ImageF(8, 4, 3, 1.0f));
  const Scene scene = full_scene(folder.path("albedo.png"), folder.path("sky.exr"));
  write_scene_json(folder.path("scene.json"), scene);
  const Scene back = read_scene_json(folder.path("scene.json"));
  ASSERT_EQ(back.objects.size(), scene.objects.size());
  for (std::size_t i = 0; i < scene.objects.size(); ++i) {
    const Object &a = scene.objects[i], &b = back.objects[i];
    EXPECT_EQ(a.name, b.name);
    EXPECT_EQ(a.id, b.id);
    EXPECT_EQ(a.shape, b.shape);
    EXPECT_EQ(a.mesh_path, b.mesh_path);
    EXPECT_EQ(a.size, b.size);
    EXPECT_TRUE(a.transform.isApprox(b.transform, 1e-12));
    EXPECT_EQ(a.material.ward.kd, b.material.ward.kd);
    EXPECT_EQ(a.material.ward.ks, b.material.ward.ks);
    EXPECT_EQ(a.material.ward.alpha, b.material.ward.alpha);
    EXPECT_EQ(a.material.kd_texture, b.material.kd_texture);
    EXPECT_EQ(a.material.texture_scale_m, b.material.texture_scale_m);
  }
  ASSERT_EQ(back.lights.size(), 1u);
  EXPECT_EQ(back.lights[0].position, scene.lights[0].position);
  EXPECT_EQ(back.lights[0].intensity, scene.lights[0].intensity);
  EXPECT_EQ(back.lights[0].proxy_radius_m, scene.lights[0].proxy_radius_m);
  ASSERT_TRUE(back.environment.has_value());
  EXPECT_EQ(back.environment->path, scene.environment->path);
  EXPECT_EQ(back.environment->scale, 0.5f);
  EXPECT_EQ(back.environment->rotation_deg, 30.0f);
  EXPECT_EQ(back.environment->samples, 16);
  const Intrinsics &k = back.camera.intrinsics, &k0 = scene.camera.intrinsics;
  EXPECT_EQ(k.width, k0.width);
  EXPECT_EQ(k.height, k0.height);
  EXPECT_EQ(k.fx, k0.fx);
  EXPECT_EQ(k.cy, k0.cy);
  EXPECT_EQ(back.camera.exposure, 0.3f);
  EXPECT_EQ(back.camera.sensor_noise, 0.01f);
  EXPECT_TRUE(back.camera.depth_noise);
  ASSERT_EQ(back.trajectory.size(), 2u);
  for (int f = 0; f < 2; ++f) EXPECT_TRUE(back.trajectory[f].isApprox(scene.trajectory[f], 1e-12));
  EXPECT_EQ(back.frames_per_second, 15);
  EXPECT_FALSE(back.shadows);
  EXPECT_EQ(back.bounces, 3);
  EXPECT_EQ(back.indirect_samples, 17);
  EXPECT_EQ(back.seed, 42u);
}

TEST(SceneJson, OrbitRelativePathsAndDefaults) {
  test::TemporaryFolder folder;
  std::ofstream(folder.path("tri.obj")) << "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n";
  io::write_json(folder.path("scene.json"), nlohmann::json::parse(R"({
    "objects": [{"shape": "mesh", "mesh": "tri.obj", "size": 1.5,
                 "transform": {"position": [1, 0, 0], "rotation": {"axis": [0, 1, 0], "angle_deg": 90}},
                 "material": {"kd": 0.4, "ks": [0.1, 0.2, 0.3], "alpha": 0.2}}],
    "trajectory": {"orbit": {"center": [0, 0.5, 0], "radius": 3, "height": 1, "frames": 8}}
  })"));
  const Scene scene = read_scene_json(folder.path("scene.json"));
  ASSERT_EQ(scene.objects.size(), 1u);
  EXPECT_EQ(scene.objects[0].mesh_path, folder.path("tri.obj"));
  EXPECT_EQ(scene.objects[0].id, 1);
  EXPECT_EQ(scene.objects[0].size, Eigen::Vector3d(1.5, 1.5, 1.5));
  EXPECT_TRUE(scene.objects[0].transform.linear().isApprox(
      Eigen::AngleAxisd(M_PI / 2, Eigen::Vector3d::UnitY()).matrix(), 1e-12));
  EXPECT_EQ(scene.objects[0].material.ward.kd, Eigen::Vector3f::Constant(0.4f));
  ASSERT_EQ(scene.trajectory.size(), 8u);
  for (const Pose& pose : scene.trajectory) {
    const Eigen::Vector3d eye = pose.translation();
    EXPECT_NEAR(Eigen::Vector2d(eye.x(), eye.z()).norm(), 3.0, 1e-9);
    EXPECT_NEAR(eye.y(), 1.5, 1e-9);
    // Camera z (third column) points at the centre.
    EXPECT_NEAR(pose.linear().col(2).dot((Eigen::Vector3d(0, 0.5, 0) - eye).normalized()), 1.0,
                1e-9);
  }
  EXPECT_EQ(scene.camera.intrinsics.width, 512);  // Kinect v2 default
  EXPECT_TRUE(scene.shadows);
  EXPECT_EQ(scene.bounces, 0);  // direct light unless asked
  EXPECT_EQ(scene.frames_per_second, 30);
}

// Writes `text` as scene.json in `folder` and returns the error reading it throws.
Error error_reading(const test::TemporaryFolder& folder, const std::string& text) {
  std::ofstream(folder.path("scene.json")) << text;
  return glint::test::error_of([&] { read_scene_json(folder.path("scene.json")); });
}

TEST(SceneJson, BadInputsNameTheFileAndTheElement) {
  test::TemporaryFolder folder;
  const std::string path = folder.path("scene.json");
  const std::string trajectory = R"("trajectory": [[0, 1, 3, 0, 0, 0, 1]])";
  const auto expect = [&](const std::string& objects, const std::string& element,
                          const std::string& reason_part) {
    const Error error =
        error_reading(folder, "{\"objects\": [" + objects + "], " + trajectory + "}");
    EXPECT_EQ(error.file(), path) << objects;
    EXPECT_EQ(error.element(), element) << objects;
    EXPECT_NE(error.reason().find(reason_part), std::string::npos) << error.what();
  };
  expect(R"({"shape": "box", "material": {"alpha": 0}})", "objects[0].material.alpha", "> 0");
  expect(R"({"shape": "box", "material": {"alpha": -0.1}})", "objects[0].material.alpha", "> 0");
  expect(R"({"shape": "box", "material": {"kd": 0.8, "ks": 0.3}})", "objects[0].material",
         "exceeds 1");
  expect(R"({"shape": "torus"})", "objects[0].shape", "unknown shape");
  expect(R"({"shape": "box", "size": [1, 0, 1]})", "objects[0].size", "> 0");
  expect(R"({"shape": "box", "colour": 1})", "objects[0]", "unknown key 'colour'");
  expect(R"({"size": 1})", "objects[0]", "missing key 'shape'");
  expect(R"({"shape": "box", "transform": {"quaternion": [0, 0, 0, 3]}})",
         "objects[0].transform.quaternion", "unit");

  // A missing mesh names the mesh file (resolved) and the element that refers to it.
  const Error mesh = error_reading(
      folder, R"({"objects": [{"shape": "mesh", "mesh": "gone.obj"}], )" + trajectory + "}");
  EXPECT_EQ(mesh.file(), folder.path("gone.obj"));
  EXPECT_EQ(mesh.element(), "objects[0].mesh");
  // Malformed JSON and an empty trajectory name the scene file.
  EXPECT_EQ(glint::test::error_of([&] { read_scene_json(kData + "broken.json"); }).file(),
            kData + "broken.json");
  const Error empty = error_reading(folder, R"({"objects": [], "trajectory": []})");
  EXPECT_EQ(empty.file(), path);
  EXPECT_EQ(empty.element(), "trajectory");
  for (const char* bad : {R"("bounces": -1)", R"("bounces": 1.5)", R"("indirect_samples": 0)"}) {
    const Error error =
        error_reading(folder, std::string(R"({"objects": [], )") + bad + ", " + trajectory + "}");
    EXPECT_EQ(error.file(), path) << bad;
    EXPECT_NE(error.reason().find("allowed range"), std::string::npos) << error.what();
  }
  EXPECT_EQ(glint::test::error_of([&] { read_scene_json(folder.path("none.json")); }).file(),
            folder.path("none.json"));
}

}  // namespace
}  // namespace glint::render
