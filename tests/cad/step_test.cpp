// STEP out and in: a generated part labels the same after a round trip; bad files are one
// clear error naming the file.
#include "cad/step.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "cad/part.h"
#include "cad/sample.h"
#include "support/error_of.h"

namespace glint::cad {
namespace {

namespace fs = std::filesystem;

class StepTest : public ::testing::Test {
 protected:
  void SetUp() override {
    folder_ = fs::temp_directory_path() /
              ("glint_step_test_" +
               std::string(::testing::UnitTest::GetInstance()->current_test_info()->name()) + "_" +
               std::to_string(::getpid()));
    fs::create_directories(folder_);
  }
  void TearDown() override { fs::remove_all(folder_); }
  std::string path(const std::string& name) const { return (folder_ / name).string(); }
  fs::path folder_;
};

TEST_F(StepTest, GeneratedPartLabelsTheSameAfterARoundTrip) {
  PartParams part_params;
  part_params.seed = 11;
  part_params.fillet_probability = 1.0;
  const Part part = random_part(part_params, 3);
  write_step(part.shape, path("part.step"));
  const TopoDS_Shape read = read_step(path("part.step"));

  const EdgeClasses before = classify_edges(part.shape, 25.0, 1e-3);
  const EdgeClasses after = classify_edges(read, 25.0, 1e-3);
  EXPECT_EQ(before.sharp, after.sharp);
  EXPECT_EQ(before.smooth, after.smooth);
  EXPECT_EQ(before.boundary, after.boundary);
  EXPECT_NEAR(before.sharp_length, after.sharp_length, 1e-3 * before.sharp_length);

  // The same points labelled against either shape's edges.
  SampleParams params;
  params.points = 20000;
  const LabelledCloud labelled = sample_shape(part.shape, params);
  const double spacing = labelled.description["median_spacing"].get<double>();
  const edges::FeatureIndex original(before.segments, params.boundary_band * spacing);
  const edges::FeatureIndex round_trip(after.segments, params.boundary_band * spacing);
  const PointCloud& cloud = labelled.cloud;
  std::size_t differ = 0;
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    const Eigen::Vector3d p = cloud.point(i).cast<double>();
    differ += original.label(p, params.band * spacing, params.boundary_band * spacing) !=
              round_trip.label(p, params.band * spacing, params.boundary_band * spacing);
  }
  EXPECT_LE(differ, cloud.size() / 1000) << differ << " of " << cloud.size();
}

TEST_F(StepTest, BadFilesAreOneClearError) {
  std::ofstream(path("garbage.step")) << "this is not a STEP file\n\x01\x02 at all";
  std::ofstream(path("empty.step"));
  PartParams part_params;
  write_step(random_part(part_params, 0).shape, path("whole.step"));
  std::ifstream whole(path("whole.step"));
  const std::string text((std::istreambuf_iterator<char>(whole)), {});
  std::ofstream(path("truncated.step")) << text.substr(0, text.size() / 3);

  for (const std::string name : {"garbage.step", "empty.step", "truncated.step", "missing.step"}) {
    const Error error = test::error_of([&] { read_step(path(name)); });
    EXPECT_EQ(error.file(), path(name));
    EXPECT_FALSE(error.reason().empty());
    EXPECT_EQ(std::string(error.what()).find('\n'), std::string::npos) << error.what();
  }
}

}  // namespace
}  // namespace glint::cad
