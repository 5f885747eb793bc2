// scene.json's numbers are bounded before they size a loop or reach a ray (docs/limits.md):
// camera, object and light coordinates within the world extent, intrinsics against the image
// size, sample counts, object ids (1..65535, unique), mesh vertices finite.
#include <gtest/gtest.h>

#include <fstream>

#include "render/mesh_loader.h"
#include "render/scene_json.h"
#include "scene_fixtures.h"
#include "support/cli_fixture.h"
#include "support/error_of.h"

namespace glint::render {
namespace {

struct Case {
  const char* json;     // the scene file
  const char* element;  // what the error names
  const char* reason;   // a part of its reason
};

TEST(SceneLimits, OutOfRangeNumbersNameTheFieldAndTheRange) {
  test::TemporaryFolder folder;
  const std::string path = folder.path("scene.json");
  const Case cases[] = {
      // The Embree assertion: a camera at 1.8e18 m.
      {R"({"objects": [], "trajectory": [[1.8e18, 0, 0, 0, 0, 0, 1]]})", "trajectory[0] position",
       "outside the world extent [-100000, 100000] m"},
      {R"({"objects": [{"shape": "box", "transform": {"position": [0, 1e30, 0]}}],
           "trajectory": [[0, 0, 3, 0, 0, 0, 1]]})",
       "objects[0].transform.position", "world extent"},
      {R"({"objects": [], "lights": [{"position": [0, 0, 1e20]}],
           "trajectory": [[0, 0, 3, 0, 0, 0, 1]]})",
       "lights[0].position", "world extent"},
      {R"({"objects": [], "trajectory": {"orbit": {"center": [0, 0, 0], "radius": 1e9,
           "frames": 2}}})",
       "trajectory[0] position", "world extent"},
      {R"({"objects": [], "trajectory": [[0, 0, 3, 0, 0, 0, 1]], "indirect_samples": 2e9})",
       "indirect_samples", "allowed range [1, 65536]"},
      {R"({"objects": [], "trajectory": [[0, 0, 3, 0, 0, 0, 1]], "bounces": 1000})", "bounces",
       "allowed range [0, 64]"},
      {R"({"objects": [{"shape": "box", "id": 0}], "trajectory": [[0, 0, 3, 0, 0, 0, 1]]})",
       "objects[0].id", "allowed range [1, 65535]"},
      {R"({"objects": [{"shape": "box", "id": 7}, {"shape": "sphere", "id": 7}],
           "trajectory": [[0, 0, 3, 0, 0, 0, 1]]})",
       "objects[1].id", "already the id of objects[0]"},
      {R"({"objects": [], "trajectory": [[0, 0, 3, 0, 0, 0, 1]], "camera": {"intrinsics":
           {"width": 64, "height": 48, "fx": -50, "fy": 50, "cx": 32, "cy": 24}}})",
       "camera.intrinsics.fx", "outside the allowed range (0, 64000] for a 64x48 image"},
      {R"({"objects": [], "trajectory": [[0, 0, 3, 0, 0, 0, 1]], "camera": {"intrinsics":
           {"width": 64, "height": 48, "fx": 50, "fy": 50, "cx": 1e9, "cy": 24}}})",
       "camera.intrinsics.cx", "allowed range [0, 64]"},
      {R"({"objects": [], "trajectory": [[0, 0, 3, 0, 0, 0, 1]], "camera": {"intrinsics":
           {"width": 20000, "height": 20000, "fx": 50, "fy": 50, "cx": 1, "cy": 1}}})",
       "camera.intrinsics", "allowed image size"},
      // A camera straight above its orbit's centre has no 'up' in its image.
      {R"({"objects": [], "trajectory": {"orbit": {"center": [0, 0, 0], "radius": 1e-12,
           "height": 2, "frames": 3}}})",
       "trajectory.orbit frame 0", "parallel to the up vector"},
  };
  for (const Case& bad : cases) {
    std::ofstream(path) << bad.json;
    const Error error = glint::test::error_of([&] { read_scene_json(path); });
    EXPECT_EQ(error.file(), path) << bad.json;
    EXPECT_EQ(error.element(), bad.element) << error.what();
    EXPECT_NE(error.reason().find(bad.reason), std::string::npos) << error.what();
  }
}

TEST(SceneLimits, EnvironmentSamplesAreBounded) {
  test::TemporaryFolder folder;
  std::ofstream(folder.path("sky.hdr")) << "";  // never opened: the bound fails first
  std::ofstream(folder.path("scene.json"))
      << R"({"objects": [], "environment": {"path": "sky.hdr", "samples": 2e9},
             "trajectory": [[0, 0, 3, 0, 0, 0, 1]]})";
  const Error error = glint::test::error_of([&] { read_scene_json(folder.path("scene.json")); });
  EXPECT_EQ(error.element(), "environment.samples");
  EXPECT_NE(error.reason().find("2000000000 is not an integer in the allowed range [1, 65536]"),
            std::string::npos)
      << error.what();
}

TEST(SceneLimits, MeshWithNonFiniteOrHugeVerticesIsRefused) {
  test::TemporaryFolder folder;
  // 1e400 overflows to infinity (and NaN once the mesh is normalised).
  std::ofstream(folder.path("inf.obj")) << "v 0 0 0\nv 1 1e400 0\nv 0 1 0\nf 1 2 3\n";
  std::ofstream(folder.path("far.obj")) << "v 0 0 0\nv 1 0 0\nv 0 1 3e38\nf 1 2 3\n";
  const Error infinite = glint::test::error_of([&] { load_mesh(folder.path("inf.obj")); });
  EXPECT_EQ(infinite.file(), folder.path("inf.obj"));
  EXPECT_EQ(infinite.element(), "vertex 1");
  EXPECT_NE(infinite.reason().find("world extent"), std::string::npos) << infinite.what();
  const Error far = glint::test::error_of([&] { load_mesh(folder.path("far.obj")); });
  EXPECT_EQ(far.element(), "vertex 2");
  EXPECT_NE(far.reason().find("world extent"), std::string::npos) << far.what();
}

// A camera at 1.8e18 m aborted `glint render` in an Embree assertion, leaving OUT.partial-PID.
TEST_F(CliTest, RenderRefusesACameraOutsideTheWorldBeforeAnyRay) {
  std::ofstream(path("scene.json"))
      << R"({"objects": [{"shape": "box"}], "trajectory": [[0, 1.8e18, 3, 0, 0, 0, 1]]})";
  const CommandResult run = glint("render " + path("scene.json") + " -o " + path("seq"));
  EXPECT_EQ(run.exit_code, 1);
  EXPECT_EQ(run.output, "glint: error: " + path("scene.json") +
                            ": trajectory[0] position: coordinate 1.8e+18 is outside the world "
                            "extent [-100000, 100000] m\n");
  for (const auto& entry : std::filesystem::directory_iterator(folder_))
    EXPECT_EQ(entry.path().filename().string().find("seq"), std::string::npos) << entry.path();
}

}  // namespace
}  // namespace glint::render
