#pragma once
// Small analytic scenes for the renderer tests: a camera at 96x72 pixels, objects, one light.
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <string>

#include "render/scene.h"
#include "render/trajectories.h"

namespace glint::render::test {

inline Intrinsics small_camera() { return {96, 72, 80.0, 80.0, 47.5, 35.5}; }

inline Object make_object(int id, ShapeKind shape, const Eigen::Vector3d& size,
                          const Eigen::Vector3d& position, const WardMaterial& ward = {}) {
  Object object;
  object.name = "object" + std::to_string(id);
  object.id = id;
  object.shape = shape;
  object.size = size;
  object.transform = Eigen::Isometry3d(Eigen::Translation3d(position));
  object.material.ward = ward;
  return object;
}

// A 4 x 4 m glossy plane at y = 0 (id 1) under one point light without a proxy, seen
// obliquely from 2 m away; shadows on, no environment.
inline Scene plane_scene() {
  Scene scene;
  WardMaterial ward;
  ward.kd = {0.5f, 0.4f, 0.3f};
  ward.ks = {0.2f, 0.25f, 0.3f};
  ward.alpha = 0.15f;
  scene.objects.push_back(make_object(1, ShapeKind::plane, {4, 1, 4}, {0, 0, 0}, ward));
  PointLight light;
  light.position = {0.3, 1.2, -0.2};
  light.intensity = {2.0f, 1.5f, 1.0f};
  light.proxy_radius_m = 0;
  scene.lights.push_back(light);
  scene.camera.intrinsics = small_camera();
  scene.trajectory = {look_at({0.2, 1.5, 1.4}, {0, 0, 0})};
  return scene;
}

// A private temporary folder per test, removed afterwards.
class TemporaryFolder {
 public:
  TemporaryFolder()
      : path_(std::filesystem::temp_directory_path() /
              ("glint_render_test_" +
               std::string(::testing::UnitTest::GetInstance()->current_test_info()->name()) + "_" +
               std::to_string(::getpid()))) {
    std::filesystem::remove_all(path_);
    std::filesystem::create_directories(path_);
  }
  ~TemporaryFolder() { std::filesystem::remove_all(path_); }
  std::string path(const std::string& name) const { return (path_ / name).string(); }

 private:
  std::filesystem::path path_;
};

}  // namespace glint::render::test
