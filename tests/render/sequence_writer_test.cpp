// The on-disk sequence: layout, units, timestamps, poses, ground truth, atomic replacement, and
// `glint render` end to end.
#include "render/sequence_writer.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "io/image_io.h"
#include "io/json_report.h"
#include "io/trajectory.h"
#include "render/renderer.h"
#include "render/scene_json.h"
#include "scene_fixtures.h"
#include "support/cli_fixture.h"
#include "support/error_of.h"

namespace glint::render {
namespace {

namespace fs = std::filesystem;

Scene three_frame_scene() {
  Scene scene = test::plane_scene();
  scene.objects.push_back(test::make_object(5, ShapeKind::sphere, {0.3, 0.3, 0.3}, {0, 0.3, 0}));
  scene.trajectory = {look_at({0.2, 1.5, 1.4}, {0, 0, 0}), look_at({0.4, 1.5, 1.3}, {0, 0, 0}),
                      look_at({0.6, 1.5, 1.2}, {0, 0, 0})};
  scene.frames_per_second = 10;
  return scene;
}

std::vector<std::string> lines_of(const std::string& path) {
  std::ifstream stream(path);
  std::vector<std::string> lines;
  for (std::string line; std::getline(stream, line);) lines.push_back(line);
  return lines;
}

TEST(SequenceWriter, WritesTheDocumentedLayout) {
  test::TemporaryFolder folder;
  const std::string out = folder.path("seq");
  const Scene scene = three_frame_scene();
  const SequenceStats stats = write_sequence(scene, out, {1, -1, true});
  EXPECT_EQ(stats.frames, 2);
  EXPECT_GT(stats.median_render_ms, 0);

  const nlohmann::json intrinsics = io::read_json(out + "/intrinsics.json");
  EXPECT_EQ(intrinsics["depth_scale"], 1000);
  EXPECT_EQ(io::read_intrinsics_json(out + "/intrinsics.json").fx, scene.camera.intrinsics.fx);
  EXPECT_EQ(lines_of(out + "/associations.txt"),
            (std::vector<std::string>{"0.100000 rgb/000001.png 0.100000 depth/000001.png",
                                      "0.200000 rgb/000002.png 0.200000 depth/000002.png"}));
  const std::vector<io::StampedPose> poses = io::read_tum_trajectory(out + "/groundtruth.txt");
  ASSERT_EQ(poses.size(), 2u);
  EXPECT_NEAR(poses[1].timestamp, 0.2, 1e-9);
  EXPECT_TRUE(poses[1].pose.isApprox(scene.trajectory[2], 1e-6));

  const FrameBuffers truth = Renderer(scene).render(scene.trajectory[2], 2);
  const ImageF depth_png = io::read_image(out + "/depth/000002.png");
  const ImageF depth_exr = io::read_image(out + "/gt/depth/000002.exr");
  const ImageF segment = io::read_image(out + "/gt/segment/000002.png");
  EXPECT_EQ(depth_exr.values(), truth.depth.values());
  for (std::size_t i = 0; i < depth_png.pixel_count(); ++i) {
    ASSERT_NEAR(depth_png.plane(0)[i] * 65535 / 1000, truth.depth.plane(0)[i], 0.0005 + 1e-6);
    ASSERT_EQ(std::lround(segment.plane(0)[i] * 65535), truth.segment.plane(0)[i]);
  }
  for (const char* map : {"gt/normal/000001.exr", "gt/kd/000001.exr", "gt/ks/000001.exr",
                          "gt/alpha/000001.exr", "rgb/000001.png"})
    EXPECT_TRUE(fs::is_regular_file(out + "/" + map)) << map;
  EXPECT_EQ(io::read_image(out + "/rgb/000001.png").channels(), 3);
  EXPECT_EQ(read_scene_json(out + "/scene.json").objects.size(), 2u);
  EXPECT_FALSE(fs::exists(out + "/rgb/000000.png"));
  // Nothing but the sequence is left in the parent folder.
  EXPECT_EQ(std::distance(fs::directory_iterator(folder.path("")), fs::directory_iterator()), 1);
}

TEST(SequenceWriter, ReplacesAPreviousSequenceButNotOtherFolders) {
  test::TemporaryFolder folder;
  const std::string out = folder.path("seq");
  write_sequence(three_frame_scene(), out, {0, 1, false});
  write_sequence(three_frame_scene(), out, {0, 2, false});
  EXPECT_EQ(lines_of(out + "/associations.txt").size(), 2u);
  EXPECT_FALSE(fs::exists(out + "/gt"));
  const std::string precious = folder.path("precious");
  fs::create_directories(precious);
  std::ofstream(precious + "/notes.txt") << "keep me";
  EXPECT_EQ(glint::test::error_of([&] { write_sequence(three_frame_scene(), precious); }).file(),
            precious);
  EXPECT_TRUE(fs::exists(precious + "/notes.txt"));
  EXPECT_EQ(glint::test::error_of([&] {
              write_sequence(three_frame_scene(), out, {3, -1, true});
            }).file(),
            out);
}

TEST(SequenceWriter, FailureLeavesNoSequenceBehind) {
  test::TemporaryFolder folder;
  Scene scene = three_frame_scene();
  scene.objects[0].material.kd_texture = folder.path("missing.png");
  const std::string out = folder.path("seq");
  EXPECT_EQ(glint::test::error_of([&] { write_sequence(scene, out); }).file(),
            folder.path("missing.png"));
  EXPECT_EQ(std::distance(fs::directory_iterator(folder.path("")), fs::directory_iterator()), 0);
}

class RenderCommand : public CliTest {};

TEST_F(RenderCommand, RendersASceneFileIntoASequence) {
  write_scene_json(path("scene.json"), three_frame_scene());
  const CommandResult result =
      glint("render " + path("scene.json") + " -o " + path("seq") +
            " --frames 2 --width 48 --no-gt --exposure 2 --report " + path("report.json"));
  ASSERT_EQ(result.exit_code, 0) << result.output;
  const nlohmann::json report = io::read_json(path("report.json"));
  EXPECT_EQ(report["frames"], 2);
  EXPECT_EQ(report["size"], nlohmann::json::array({48, 36}));
  EXPECT_EQ(io::read_image(path("seq/rgb/000001.png")).width(), 48);
  EXPECT_FALSE(fs::exists(path("seq/gt")));
  EXPECT_DOUBLE_EQ(read_scene_json(path("seq/scene.json")).camera.exposure, 2.0);
}

TEST_F(RenderCommand, BadSceneGivesOneClearLine) {
  std::ofstream(path("scene.json")) << R"({"objects": [{"shape": "box", "material": {"alpha": 0}}],
                                          "trajectory": [[0, 0, 3, 0, 0, 0, 1]]})";
  const CommandResult result = glint("render " + path("scene.json") + " -o " + path("seq"));
  EXPECT_EQ(result.exit_code, 1);
  EXPECT_NE(result.output.find("alpha"), std::string::npos) << result.output;
  EXPECT_NE(result.output.find("scene.json"), std::string::npos) << result.output;
  EXPECT_FALSE(fs::exists(path("seq")));
}

}  // namespace
}  // namespace glint::render
