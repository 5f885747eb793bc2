// The training-set generator: material ranges, determinism, object and lights placement, and
// writing/resuming a tiny set (primitives only, so no data folder is needed; the mesh shapes
// are checked when ../shared/data is there).
#include "render/training_set.h"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <nlohmann/json.hpp>

#include "core/error.h"
#include "io/json_report.h"
#include "render/perceptual.h"

namespace glint::render {
namespace {
namespace fs = std::filesystem;

TrainingSetParams primitive_params() {
  TrainingSetParams params;
  params.shapes = {"sphere", "box"};
  params.environment_probability = 0;
  params.frames = 4;
  params.width = 40;
  params.height = 33;
  params.seed = 7;
  return params;
}

std::string shared_data_dir() {
  const char* data = std::getenv("GLINT_DATA");
  return data && *data ? data : GLINT_TEST_DATA_DIR "/../../../shared/data";
}

TEST(TrainingMaterials, CoverTheDocumentedRanges) {
  const MaterialRanges ranges;
  SeededDraw draw(3);
  float kd_low = 1, kd_high = 0, c_high = 0, alpha_low = 1, alpha_high = 0;
  int glossy = 0, rough = 0;
  const int samples = 4000;
  for (int i = 0; i < samples; ++i) {
    const WardMaterial m = sample_training_material(ranges, draw);
    ASSERT_LE((m.kd + m.ks).maxCoeff(), 1.0f);
    ASSERT_GE(m.kd.minCoeff(), ranges.kd_min);
    ASSERT_LE(m.kd.maxCoeff(), ranges.kd_max);
    ASSERT_GE(m.ks.minCoeff(), 0.0f);
    ASSERT_GE(m.alpha, ranges.alpha_min);
    ASSERT_LE(m.alpha, ranges.alpha_max);
    const PerceptualWard p = to_perceptual(m);
    ASSERT_LE(p.c.maxCoeff(), ranges.c_max + 1e-4f);
    kd_low = std::min(kd_low, m.kd.minCoeff());
    kd_high = std::max(kd_high, m.kd.maxCoeff());
    c_high = std::max(c_high, p.c.maxCoeff());
    alpha_low = std::min(alpha_low, m.alpha);
    alpha_high = std::max(alpha_high, m.alpha);
    glossy += m.alpha < 0.05f;
    rough += m.alpha > 0.2f;
  }
  EXPECT_LT(kd_low, 0.06f);
  EXPECT_GT(kd_high, 0.85f);
  EXPECT_GT(c_high, 0.19f);
  EXPECT_LT(alpha_low, 0.021f);
  EXPECT_GT(alpha_high, 0.34f);
  // Log-uniform: about a third of the draws lie below 0.05 and a fifth above 0.2.
  EXPECT_GT(glossy, samples / 4);
  EXPECT_GT(rough, samples / 8);
}

// Of the kept draws (inside the kd range), chroma uniform in radius puts about 1 in 7 within 5 of
// the grey axis, a, b uniform in a square about 1 in 77 (seed 5: 590 and 52 of 4000).
TEST(TrainingMaterials, NearGreyShareMakesNearGreysCommon) {
  const auto near_greys = [](float share) {
    MaterialRanges ranges;
    ranges.near_grey_share = share;
    SeededDraw draw(5);
    int count = 0;
    for (int i = 0; i < 4000; ++i) {
      const WardMaterial m = sample_training_material(ranges, draw);
      EXPECT_GE(m.kd.minCoeff(), ranges.kd_min);
      EXPECT_LE(m.kd.maxCoeff(), ranges.kd_max);
      const Eigen::Vector3f lab = linear_rgb_to_lab(m.kd);
      count += std::hypot(lab.y(), lab.z()) < 5;
    }
    return count;
  };
  const int square = near_greys(0), half = near_greys(0.5f), radius = near_greys(1);
  EXPECT_LT(square, 4000 / 50);
  EXPECT_GT(radius, 4000 / 10);
  EXPECT_GT(half, 3 * square);
  EXPECT_LT(half, radius);
  // The set's recorded parameters name the share only when it is used, so that sets made
  // before the option keep their parameters and resume.
  TrainingSetParams params;
  EXPECT_FALSE(training_set_parameters_json(params)["ranges"].contains("near_grey_share"));
  params.ranges.near_grey_share = 0.5f;
  EXPECT_EQ(training_set_parameters_json(params)["ranges"]["near_grey_share"], 0.5f);
}

TEST(TrainingScenes, SameSeedSameSceneOtherIndexOtherScene) {
  const TrainingSetParams params = primitive_params();
  const Scene a = make_training_scene(params, 5), b = make_training_scene(params, 5);
  const Scene c = make_training_scene(params, 6);
  ASSERT_EQ(a.objects.size(), 1u);
  EXPECT_EQ(a.objects[0].name, b.objects[0].name);
  EXPECT_TRUE(a.objects[0].size.isApprox(b.objects[0].size));
  EXPECT_TRUE(a.objects[0].transform.isApprox(b.objects[0].transform));
  EXPECT_EQ(a.objects[0].material.ward.kd, b.objects[0].material.ward.kd);
  EXPECT_EQ(a.objects[0].material.ward.alpha, b.objects[0].material.ward.alpha);
  ASSERT_EQ(a.lights.size(), b.lights.size());
  for (std::size_t l = 0; l < a.lights.size(); ++l)
    EXPECT_EQ(a.lights[l].position, b.lights[l].position);
  ASSERT_EQ(a.trajectory.size(), b.trajectory.size());
  for (std::size_t i = 0; i < a.trajectory.size(); ++i)
    EXPECT_TRUE(a.trajectory[i].isApprox(b.trajectory[i]));
  EXPECT_EQ(a.seed, b.seed);
  EXPECT_NE(a.objects[0].material.ward.kd, c.objects[0].material.ward.kd);
  EXPECT_NE(a.seed, c.seed);
}

TEST(TrainingScenes, ObjectInViewLightsOutsideIt) {
  const TrainingSetParams params = primitive_params();
  for (int index = 0; index < 50; ++index) {
    const Scene scene = make_training_scene(params, index);
    const Object& object = scene.objects[0];
    EXPECT_EQ(object.id, 1);
    EXPECT_FALSE(scene.environment.has_value());
    ASSERT_GE(scene.lights.size(), 1u);
    ASSERT_LE(scene.lights.size(), 3u);
    EXPECT_EQ(scene.trajectory.size(), 4u);
    const Eigen::Vector3d centre = object.transform.translation();
    const double radius =
        object.shape == ShapeKind::sphere ? object.size.x() : object.size.norm() / 2;
    EXPECT_NEAR(centre.y(), object.shape == ShapeKind::sphere ? radius : object.size.y() / 2,
                1e-12);  // resting on y = 0
    for (const PointLight& light : scene.lights) {
      const double distance = (light.position - centre).norm();
      EXPECT_GE(distance, std::max(1.0, radius + 0.3) - 1e-9);
      EXPECT_LE(distance, 3.0 + 1e-9);
      EXPECT_GT(light.position.y(), centre.y());
    }
    for (const Pose& pose : scene.trajectory) {
      const Eigen::Vector3d in_camera = pose.inverse() * centre;
      const Eigen::Vector2d pixel = scene.camera.intrinsics.project(in_camera);
      EXPECT_NEAR(pixel.x(), scene.camera.intrinsics.cx, 1e-6);
      EXPECT_NEAR(pixel.y(), scene.camera.intrinsics.cy, 1e-6);
      EXPECT_GT(in_camera.z(), radius);  // the camera is outside the object
    }
  }
}

TEST(TrainingScenes, UnknownShapeThrows) {
  TrainingSetParams params = primitive_params();
  params.shapes = {"sphere", "dodecahedron"};
  EXPECT_THROW(make_training_scene(params, 0), Error);
}

TEST(TrainingScenes, MeshShapesFitTheirBoundingSphere) {
  TrainingSetParams params = primitive_params();
  params.data_dir = shared_data_dir();
  if (!fs::exists(fs::path(params.data_dir) / "meshes" / "cow.obj"))
    GTEST_SKIP() << "no mesh data in " << params.data_dir;
  params.shapes = {"cow", "bunny", "rocker-arm"};
  for (int index = 0; index < 6; ++index) {
    const Scene scene = make_training_scene(params, index);
    EXPECT_EQ(scene.objects[0].shape, ShapeKind::mesh);
    EXPECT_TRUE(fs::exists(scene.objects[0].mesh_path));
    // The camera distance grows with the long cow's bounding sphere, not only its height.
    const double distance =
        (scene.trajectory[0].translation() - Eigen::Vector3d(0, scene.objects[0].size.y() / 2, 0))
            .norm();
    EXPECT_GT(distance, scene.objects[0].size.y());
  }
}

TEST(TrainingSet, WritesIndexSkipsCompleteSequencesAndRefusesOtherParameters) {
  const fs::path out = fs::temp_directory_path() / "glint_training_set_test";
  fs::remove_all(out);
  TrainingSetParams params = primitive_params();
  params.sequences = 2;
  params.frames = 2;
  int callbacks = 0;
  const TrainingSetStats first = write_training_set(params, out.string(), [&] { ++callbacks; });
  EXPECT_EQ(first.rendered, 2);
  EXPECT_EQ(first.skipped, 0);
  EXPECT_EQ(callbacks, 2);
  for (const char* folder : {"seq_00000", "seq_00001"}) {
    EXPECT_TRUE(fs::exists(out / folder / "groundtruth.txt")) << folder;
    EXPECT_TRUE(fs::exists(out / folder / "scene.json")) << folder;
    EXPECT_TRUE(fs::is_directory(out / folder / "gt" / "kd")) << folder;
  }
  const nlohmann::json index = io::read_json((out / "index.json").string());
  EXPECT_EQ(index["count"], 2);
  ASSERT_EQ(index["sequences"].size(), 2u);
  EXPECT_EQ(index["sequences"][1]["folder"], "seq_00001");
  EXPECT_EQ(index["parameters"]["ranges"]["alpha"][1], 0.35f);

  // Extending the set renders only the new sequence.
  params.sequences = 3;
  const TrainingSetStats resumed = write_training_set(params, out.string());
  EXPECT_EQ(resumed.rendered, 1);
  EXPECT_EQ(resumed.skipped, 2);

  params.frames = 3;
  EXPECT_THROW(write_training_set(params, out.string()), Error);
  fs::remove_all(out);
}

}  // namespace
}  // namespace glint::render
