// A cloud far from 0 (a scan in map coordinates) is classified like the same cloud at 0: its
// positions are re-centred in double before they become float (core/point_cloud.h). Read as
// float at a 10^7 m offset, 16 % of such a cloud's labels changed.
#include <fmt/format.h>
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "edges/classifier.h"
#include "edges/features.h"
#include "edges/model.h"
#include "edges/synth.h"
#include "io/ply.h"
#include "support/error_of.h"

namespace glint::edges {
namespace {

// The cloud as an ascii PLY with double positions, shifted by `offset`.
void write_shifted(const std::string& path, const PointCloud& cloud, double offset) {
  std::ofstream out(path);
  out << fmt::format(
      "ply\nformat ascii 1.0\nelement vertex {}\nproperty double x\nproperty double y\n"
      "property double z\nend_header\n",
      cloud.size());
  for (std::size_t i = 0; i < cloud.size(); ++i)
    out << fmt::format("{:.17g} {:.17g} {:.17g}\n", cloud.x[i] + offset, cloud.y[i] + offset,
                       double(cloud.z[i]));
}

TEST(FarCloud, LabelsAtA1e7OffsetAreThoseAtTheOrigin) {
  SynthParams params;
  params.min_points = params.max_points = 6000;
  const PointCloud cloud = synthesize_cloud(params, 3).cloud;
  const std::filesystem::path folder =
      std::filesystem::temp_directory_path() / fmt::format("glint_far_cloud_{}", ::getpid());
  std::filesystem::create_directories(folder);
  write_shifted((folder / "near.ply").string(), cloud, 0);
  write_shifted((folder / "far.ply").string(), cloud, 1e7);
  const PointCloud near = io::read_ply((folder / "near.ply").string());
  const PointCloud far = io::read_ply((folder / "far.ply").string());
  std::filesystem::remove_all(folder);
  EXPECT_NEAR(far.origin.x(), 1e7, 1.0);

  const Model model =
      Model::load(std::string(GLINT_TEST_DATA_DIR) + "/../../models/bounded-3c.json");
  const Classification at_origin = classify(near, model), far_away = classify(far, model);
  std::size_t changed = 0;
  for (std::size_t i = 0; i < near.size(); ++i)
    changed += at_origin.labels[i] != far_away.labels[i];
  // The positions differ at most by float rounding of a whole-metre shift.
  EXPECT_LE(changed, near.size() / 1000) << changed << " of " << near.size() << " labels changed";
}

// Squared distances of a coordinate of 1e37 overflow float: NaN probabilities, before.
TEST(FarCloud, CoordinateBeyondTheFeatureRangeIsAnError) {
  SynthParams params;
  params.min_points = params.max_points = 4000;
  PointCloud cloud = synthesize_cloud(params, 1).cloud;
  cloud.z[5] = 1e37f;
  const Error error = glint::test::error_of([&] { compute_features(cloud); });
  EXPECT_EQ(error.element(), "point 5");
  EXPECT_NE(error.reason().find("is more than 1e+09 from the cloud's origin"), std::string::npos)
      << error.what();
}

}  // namespace
}  // namespace glint::edges
