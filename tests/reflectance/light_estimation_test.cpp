// Lighting estimation (paper 1 §3.2): positions and physically measured intensities from a
// rendered light capture of the built-in cubes scene (no data folder needed), clipping,
// lights.json round trip and bad inputs.
#include "reflectance/light_estimation.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <filesystem>
#include <fstream>

#include "io/json_report.h"
#include "io/rgbd_sequence.h"
#include "render/builtin_scenes.h"
#include "render/sequence_writer.h"
#include "support/cli_fixture.h"
#include "support/error_of.h"

namespace glint::reflectance {
namespace {

namespace fs = std::filesystem;

fs::path scratch_folder() {
  return fs::temp_directory_path() / ("glint_light_estimation_test_" + std::to_string(::getpid()));
}

// The cubes capture at 256x212 over 24 frames (its lights appear 4-6 px wide).
render::Scene cubes_capture(float exposure = render::kLightCaptureExposure) {
  render::BuiltinOptions options;
  options.data_dir = "DATA";  // cubes loads no file
  options.frames = 1;
  options.width = 256;
  options.height = 212;
  render::LightCaptureParams path;
  path.frames = 24;
  return render::make_light_capture(render::make_builtin_scene("cubes", options), path, exposure);
}

io::RgbdSequence write_capture(const render::Scene& capture, const std::string& name) {
  const std::string folder = (scratch_folder() / name).string();
  render::SequenceOptions options;
  options.ground_truth = false;
  options.progress = false;
  render::write_sequence(capture, folder, options);
  return io::open_rgbd_sequence(folder);
}

// The ground-truth light nearest to `light`.
const render::PointLight& nearest(const std::vector<render::PointLight>& truth,
                                  const render::PointLight& light) {
  const render::PointLight* best = &truth.front();
  for (const render::PointLight& t : truth)
    if ((t.position - light.position).norm() < (best->position - light.position).norm()) best = &t;
  return *best;
}

class CubesCapture : public testing::Test {
 protected:
  static void SetUpTestSuite() {
    fs::create_directories(scratch_folder());
    scene_ = new render::Scene(cubes_capture());
    sequence_ = new io::RgbdSequence(write_capture(*scene_, "cubes"));
  }
  static void TearDownTestSuite() {
    delete scene_;
    delete sequence_;
    fs::remove_all(scratch_folder());
  }
  static render::Scene* scene_;
  static io::RgbdSequence* sequence_;
};
render::Scene* CubesCapture::scene_ = nullptr;
io::RgbdSequence* CubesCapture::sequence_ = nullptr;

TEST_F(CubesCapture, FindsEveryLightWithinThreeCentimetresAndTenPercent) {
  const LightEstimate estimate = estimate_lights(*sequence_);
  EXPECT_FLOAT_EQ(estimate.exposure, render::kLightCaptureExposure);  // from scene.json
  ASSERT_EQ(estimate.lights.size(), scene_->lights.size());
  ASSERT_EQ(estimate.support.size(), scene_->lights.size());
  for (std::size_t l = 0; l < estimate.lights.size(); ++l) {
    const render::PointLight& light = estimate.lights[l];
    const render::PointLight& truth = nearest(scene_->lights, light);
    EXPECT_LT((light.position - truth.position).norm(), 0.03) << l;
    for (int c = 0; c < 3; ++c)
      EXPECT_NEAR(light.intensity[c] / truth.intensity[c], 1.0, 0.1) << l << " channel " << c;
    EXPECT_NEAR(light.proxy_radius_m, truth.proxy_radius_m, 0.01) << l;
    EXPECT_GE(estimate.support[l].frames, 8) << l;
    EXPECT_GT(estimate.support[l].pixels, 100) << l;
    EXPECT_LT(estimate.support[l].position_spread_m, 0.03) << l;
    EXPECT_EQ(estimate.support[l].clipped_fraction, 0) << l;
  }
}

TEST_F(CubesCapture, FlatEmittersKeepTheCentroidOnTheCameraFacingCap) {
  LightEstimationParams params;
  params.spherical_emitters = false;
  const LightEstimate estimate = estimate_lights(*sequence_, params);
  ASSERT_EQ(estimate.lights.size(), scene_->lights.size());
  for (const render::PointLight& light : estimate.lights) {
    const render::PointLight& truth = nearest(scene_->lights, light);
    // The cameras look up at the lights: the seen cap is 2r/3 = 3.3 cm in front of the centre.
    EXPECT_LT(light.position.y(), truth.position.y() - 0.005);
    EXPECT_LT((light.position - truth.position).norm(), 0.05);
    // Pixels nearer than the centre: the intensity comes out a few percent low.
    EXPECT_LT(light.intensity.sum(), truth.intensity.sum());
    EXPECT_GT(light.intensity.sum(), 0.9 * truth.intensity.sum());
  }
}

TEST_F(CubesCapture, IntensityScalesWithTheInverseOfTheExposure) {
  LightEstimationParams params;
  params.exposure = 2 * render::kLightCaptureExposure;
  const LightEstimate halved = estimate_lights(*sequence_, params);
  const LightEstimate reference = estimate_lights(*sequence_);
  ASSERT_EQ(halved.lights.size(), reference.lights.size());
  for (std::size_t l = 0; l < halved.lights.size(); ++l)
    EXPECT_TRUE(halved.lights[l].intensity.isApprox(0.5f * reference.lights[l].intensity, 1e-5f));
}

TEST_F(CubesCapture, ABrightThresholdAboveEveryProxyFindsNothing) {
  LightEstimationParams params;
  params.min_luminance = 0.95f;
  int frames = 0;
  EXPECT_TRUE(estimate_lights(*sequence_, params, [&] { ++frames; }).lights.empty());
  EXPECT_EQ(frames, int(sequence_->frames.size()));
}

// The main cubes sequence, normally exposed, given as a capture: most lit surfaces pass the
// threshold, and the run is an error naming a frame's colour image instead of mean shift over
// most of its pixels.
TEST_F(CubesCapture, ANormallyExposedFrameIsNoCapture) {
  render::BuiltinOptions options;
  options.data_dir = "DATA";
  options.frames = 2;
  options.width = 256;
  options.height = 212;
  const io::RgbdSequence sequence =
      write_capture(render::make_builtin_scene("cubes", options), "normal");
  const Error error = test::error_of([&] { estimate_lights(sequence); });
  EXPECT_TRUE(
      std::any_of(sequence.frames.begin(), sequence.frames.end(),
                  [&](const io::RgbdFrameFiles& f) { return f.colour_path == error.file(); }))
      << error.file();
  EXPECT_NE(error.reason().find("not a low-exposure light capture"), std::string::npos)
      << error.reason();
}

TEST_F(CubesCapture, AFrameWithoutAPoseIsAnErrorNamingTheSequence) {
  io::RgbdSequence without_pose = *sequence_;
  without_pose.frames[3].ground_truth.reset();
  const Error error = test::error_of([&] { estimate_lights(without_pose); });
  EXPECT_EQ(error.file(), sequence_->folder);
  EXPECT_NE(error.element().find("frame 3"), std::string::npos) << error.element();
}

TEST_F(CubesCapture, ClippedProxiesAreReportedAndGiveALowerBound) {
  render::Scene bright = *scene_;
  bright.camera.exposure = 20 * render::kLightCaptureExposure;  // proxies read 6-15: clipped
  bright.trajectory.resize(6);
  const io::RgbdSequence sequence = write_capture(bright, "clipped");
  LightEstimationParams params;
  params.min_luminance = 0.5f;  // at this exposure glossy highlights pass 0.05
  params.fusion.min_frames = 2;
  const LightEstimate estimate = estimate_lights(sequence, params);
  ASSERT_FALSE(estimate.lights.empty());
  for (std::size_t l = 0; l < estimate.lights.size(); ++l) {
    const render::PointLight& truth = nearest(scene_->lights, estimate.lights[l]);
    EXPECT_GT(estimate.support[l].clipped_fraction, 0.9) << l;
    EXPECT_LT(estimate.lights[l].intensity.maxCoeff(), 0.5f * truth.intensity.minCoeff()) << l;
  }
}

TEST_F(CubesCapture, LightsJsonRoundTrips) {
  const LightEstimate estimate = estimate_lights(*sequence_);
  const std::string path = (scratch_folder() / "lights.json").string();
  write_lights_json(path, estimate);
  const LightEstimate read = read_lights_json(path);
  EXPECT_EQ(read.capture, estimate.capture);
  EXPECT_FLOAT_EQ(read.exposure, estimate.exposure);
  ASSERT_EQ(read.lights.size(), estimate.lights.size());
  for (std::size_t l = 0; l < read.lights.size(); ++l) {
    EXPECT_TRUE(read.lights[l].position.isApprox(estimate.lights[l].position, 1e-12));
    EXPECT_TRUE(read.lights[l].intensity.isApprox(estimate.lights[l].intensity, 1e-6f));
    EXPECT_DOUBLE_EQ(read.lights[l].proxy_radius_m, estimate.lights[l].proxy_radius_m);
    EXPECT_EQ(read.support[l].frames, estimate.support[l].frames);
    EXPECT_DOUBLE_EQ(read.support[l].pixels, estimate.support[l].pixels);
    EXPECT_DOUBLE_EQ(read.support[l].position_spread_m, estimate.support[l].position_spread_m);
  }
}

class LightsJson : public testing::Test {
 protected:
  void SetUp() override { fs::create_directories(scratch_folder()); }
  void TearDown() override { fs::remove_all(scratch_folder()); }

  // Writes `text` to a file and returns the error reading it gives.
  static Error error_reading(const std::string& text) {
    const std::string path = (scratch_folder() / "bad.json").string();
    std::ofstream(path) << text;
    Error error = test::error_of([&] { read_lights_json(path); });
    EXPECT_EQ(error.file(), path);
    return error;
  }
};

TEST_F(LightsJson, ReadsTheMinimalForm) {
  const std::string path = (scratch_folder() / "lights.json").string();
  std::ofstream(path) << R"({"lights": [{"position": [1, 2.5, -1], "intensity": [10, 9, 8]}]})";
  const LightEstimate read = read_lights_json(path);
  ASSERT_EQ(read.lights.size(), 1u);
  EXPECT_TRUE(read.lights[0].position.isApprox(Eigen::Vector3d(1, 2.5, -1)));
  EXPECT_TRUE(read.lights[0].intensity.isApprox(Eigen::Vector3f(10, 9, 8)));
  EXPECT_FLOAT_EQ(read.exposure, 1);
  EXPECT_EQ(read.support[0].frames, 0);
}

TEST_F(LightsJson, BadFilesNameTheElement) {
  EXPECT_EQ(error_reading(R"({"light": []})").element(), "");
  EXPECT_EQ(error_reading(R"({"lights": [{"intensity": [1, 1, 1]}]})").element(), "lights[0]");
  EXPECT_EQ(
      error_reading(R"({"lights": [{"position": [0, 2, 0], "intensity": [1, 1]}]})").element(),
      "lights[0].intensity");
  EXPECT_EQ(error_reading(R"({"lights": [{"position": [0, 2, 0], "intensity": [1, 1, 1]},
                                         {"position": [0, null, 0], "intensity": [1, 1, 1]}]})")
                .element(),
            "lights[1].position[1]");
  EXPECT_NE(error_reading(R"({"lights": [{"position": [NaN, 2, 0], "intensity": [1, 1, 1]}]})")
                .reason()
                .find("not valid JSON"),
            std::string::npos);
  EXPECT_EQ(
      error_reading(R"({"lights": [{"position": [0, 2, 0], "intensity": [1, -1, 1]}]})").element(),
      "lights[0].intensity");
  EXPECT_EQ(error_reading(R"({"lights": [], "exposure": 0})").element(), "exposure");
  EXPECT_EQ(error_reading(R"({"lights": [{"position": [0, 2, 0], "intensity": [1, 1, 1],
                                          "frames": 2.5}]})")
                .element(),
            "lights[0].frames");
}

TEST_F(LightsJson, CaptureExposureComesFromSceneJson) {
  const fs::path folder = scratch_folder() / "capture";
  fs::create_directories(folder);
  EXPECT_FLOAT_EQ(capture_exposure(folder.string()), 1);  // no scene.json
  std::ofstream((folder / "scene.json").string()) << R"({"camera": {"exposure": 0.002}})";
  EXPECT_FLOAT_EQ(capture_exposure(folder.string()), 0.002f);
  std::ofstream((folder / "scene.json").string()) << R"({"camera": {"exposure": -1}})";
  EXPECT_EQ(test::error_of([&] { capture_exposure(folder.string()); }).element(),
            "camera.exposure");
}

using LightsCli = CliTest;

TEST_F(LightsCli, WritesLightsJsonAndComparesWithTheGroundTruth) {
  ASSERT_EQ(glint("synth lights --scene cubes --width 256 --frames 24 --no-gt -o " + path("cap"))
                .exit_code,
            0);
  const CommandResult result = glint("lights " + path("cap") + " -o " + path("lights.json") +
                                     " --report " + path("report.json"));
  ASSERT_EQ(result.exit_code, 0) << result.output;
  EXPECT_NE(result.output.find("position error"), std::string::npos) << result.output;
  EXPECT_EQ(read_lights_json(path("lights.json")).lights.size(), 2u);
  const nlohmann::json report = io::read_json(path("report.json"));
  ASSERT_EQ(report["ground_truth"].size(), 2u);
  for (const nlohmann::json& light : report["ground_truth"])
    EXPECT_LT(light["position_error_m"].get<double>(), 0.03);
}

TEST_F(LightsCli, AMissingCaptureFailsWithOneLineAndNoOutput) {
  const CommandResult result = glint("lights " + path("nothing") + " -o " + path("lights.json"));
  EXPECT_EQ(result.exit_code, 1);
  EXPECT_NE(result.output.find("nothing"), std::string::npos) << result.output;
  EXPECT_FALSE(fs::exists(path("lights.json")));
}

}  // namespace
}  // namespace glint::reflectance
