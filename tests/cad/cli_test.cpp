// `glint edges synth --kind cad` and `glint edges label` end to end, and a bad STEP file's
// one-line error.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <utility>
#include <vector>

#include "cad/part.h"
#include "cad/step.h"
#include "io/ply.h"
#include "support/cli_fixture.h"

namespace glint {
namespace {

namespace fs = std::filesystem;

TEST_F(CliTest, CadSynthThenLabelAStepPart) {
  const CommandResult synth = glint("edges synth --kind cad -o " + path("cad") +
                                    " --count 2 --seed 4 --min-points 1500 --max-points 2000");
  ASSERT_EQ(synth.exit_code, 0) << synth.output;
  const auto manifest = nlohmann::json::parse(std::ifstream(path("cad/manifest.json")));
  ASSERT_EQ(manifest["clouds"].size(), 2u);
  EXPECT_TRUE(manifest["clouds"][0]["part"].contains("operations"));
  EXPECT_TRUE(fs::exists(path("cad/" + manifest["clouds"][0]["file"].get<std::string>())));

  cad::write_step(cad::random_part(cad::PartParams{}, 2).shape, path("part.step"));
  const CommandResult label = glint("edges label " + path("part.step") + " -o " + path("part.ply") +
                                    " --points 3000 --report " + path("label.json"));
  ASSERT_EQ(label.exit_code, 0) << label.output;
  const PointCloud cloud = io::read_ply(path("part.ply"));
  EXPECT_EQ(cloud.size(), 3000u);
  ASSERT_TRUE(cloud.get<std::uint8_t>("label"));
  const auto report = nlohmann::json::parse(std::ifstream(path("label.json")));
  EXPECT_GT(report["cloud"]["labels"]["sharp-edge"].get<int>(), 0);

  // Cut open on the B-rep: the cut is a boundary; the mesh-only --cut-mode is refused.
  const CommandResult cut = glint("edges label " + path("part.step") + " -o " + path("cut.ply") +
                                  " --points 3000 --cut-plane 0,0,1 --report " + path("cut.json"));
  ASSERT_EQ(cut.exit_code, 0) << cut.output;
  const auto cut_report = nlohmann::json::parse(std::ifstream(path("cut.json")));
  EXPECT_GT(cut_report["cloud"]["brep_edges"]["boundary"].get<int>(), 0);
  EXPECT_GT(cut_report["cloud"]["labels"]["boundary"].get<int>(), 0);
  const CommandResult refused = glint("edges label " + path("part.step") + " -o " +
                                      path("drop.ply") + " --cut-plane 0,0,1 --cut-mode drop");
  EXPECT_EQ(refused.exit_code, 1) << refused.output;
  EXPECT_NE(refused.output.find("--cut-mode"), std::string::npos) << refused.output;
  EXPECT_FALSE(fs::exists(path("drop.ply")));
  std::ofstream(path("features.yml")) << "curves: []\n";
  const CommandResult features =
      glint("edges label " + path("part.step") + " -o " + path("drop.ply") + " --abc-features " +
            path("features.yml"));
  EXPECT_EQ(features.exit_code, 1) << features.output;
  EXPECT_NE(features.output.find("--abc-features"), std::string::npos) << features.output;
}

TEST_F(CliTest, LabelNamesABadStepFileInOneLine) {
  std::ofstream(path("bad.step")) << "ISO-10303-21;\nHEADER;\nFILE_DESCRIPTION((";
  const CommandResult label = glint("edges label " + path("bad.step") + " -o " + path("out.ply"));
  EXPECT_EQ(label.exit_code, 1);
  EXPECT_NE(label.output.find("bad.step"), std::string::npos) << label.output;
  EXPECT_EQ(std::count(label.output.begin(), label.output.end(), '\n'), 1) << label.output;
  EXPECT_FALSE(fs::exists(path("out.ply")));
}

// The unit cube as an OBJ: 8 corners, 12 triangles.
void write_cube_obj(const std::string& file) {
  std::ofstream obj(file);
  for (int i = 0; i < 8; ++i)
    obj << "v " << (i & 1) << ' ' << ((i >> 1) & 1) << ' ' << (i >> 2) << '\n';
  obj << "f 1 3 4\nf 1 4 2\nf 5 6 8\nf 5 8 7\nf 1 2 6\nf 1 6 5\n"
         "f 3 7 8\nf 3 8 4\nf 1 5 7\nf 1 7 3\nf 2 4 8\nf 2 8 6\n";
}

TEST_F(CliTest, LabelAMeshAtItsVerticesAndCutOpen) {
  write_cube_obj(path("cube.obj"));
  const CommandResult closed =
      glint("edges label " + path("cube.obj") + " -o " + path("cube.ply") + " --sampling vertices");
  ASSERT_EQ(closed.exit_code, 0) << closed.output;
  const PointCloud corners = io::read_ply(path("cube.ply"));
  ASSERT_EQ(corners.size(), 8u);
  for (std::uint8_t label : *corners.get<std::uint8_t>("label")) EXPECT_EQ(label, 1);

  const CommandResult cut =
      glint("edges label " + path("cube.obj") + " -o " + path("cut.ply") +
            " --points 4000 --cut-plane 0,0,1,0.1 --report " + path("cut.json"));
  ASSERT_EQ(cut.exit_code, 0) << cut.output;
  const auto report = nlohmann::json::parse(std::ifstream(path("cut.json")));
  // The plane z = 0.5 + 0.1 * sqrt(3) keeps the top; the cut is the four sides' border.
  EXPECT_NEAR(report["cut_plane"]["point"][2].get<double>(), 0.5 + 0.1 * std::sqrt(3.0), 1e-12);
  EXPECT_NEAR(report["cloud"]["mesh_edges"]["boundary_length"].get<double>(), 4.0, 1e-9);
  const PointCloud cloud = io::read_ply(path("cut.ply"));
  const auto& labels = *cloud.get<std::uint8_t>("label");
  int boundary = 0;
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    EXPECT_GE(cloud.point(i).z(), 0.5f + 0.1f * std::sqrt(3.0f) - 1e-5f);
    if (labels[i] == 2) {
      ++boundary;
      EXPECT_LT(cloud.point(i).z(), 0.5f + 0.1f * std::sqrt(3.0f) + 0.05f);
    }
  }
  EXPECT_GT(boundary, 0);
}

TEST_F(CliTest, LabelRefusesWhatAMeshCannotGiveInOneLine) {
  write_cube_obj(path("cube.obj"));
  for (const std::string& arguments :
       {std::string(" --deflection 0.01"), std::string(" --cut-plane 0,0,1,2"),
        std::string(" --cut-plane 0,0,0")}) {
    const CommandResult label =
        glint("edges label " + path("cube.obj") + " -o " + path("out.ply") + arguments);
    EXPECT_EQ(label.exit_code, 1) << arguments;
    EXPECT_EQ(std::count(label.output.begin(), label.output.end(), '\n'), 1) << label.output;
    EXPECT_FALSE(fs::exists(path("out.ply")));
  }
  // Neither a part nor a mesh.
  std::ofstream(path("part.stl")) << "solid part\nendsolid part\n";
  const CommandResult stl = glint("edges label " + path("part.stl") + " -o " + path("out.ply"));
  EXPECT_EQ(stl.exit_code, 1);
  EXPECT_NE(stl.output.find(".step, .stp, .obj or .ply"), std::string::npos) << stl.output;
  // A point cloud has no surface to label.
  PointCloud points;
  points.push_back(0, 0, 0);
  io::write_ply(path("points.ply"), points);
  const CommandResult label = glint("edges label " + path("points.ply") + " -o " + path("out.ply"));
  EXPECT_EQ(label.exit_code, 1);
  EXPECT_NE(label.output.find("points.ply"), std::string::npos) << label.output;
  EXPECT_FALSE(fs::exists(path("out.ply")));
}

// An ABC features file for the cube of write_cube_obj: the top's edges y = 0 and x = 1 form
// one sharp curve (vertices 4, 5, 7), the bottom's edge y = 0 a curve flagged smooth.
void write_cube_features(const std::string& file) {
  std::ofstream(file) << "curves:\n- sharp: true\n  type: Line\n  vert_indices: [4, 5, 7]\n"
                         "- sharp: false\n  type: Line\n  vert_indices: [0, 1]\n"
                         "surfaces:\n- type: Plane\n  vert_indices: [0, 1, 2, 3]\n";
}

TEST_F(CliTest, LabelAnAbcMeshFromItsFeaturesFile) {
  write_cube_obj(path("cube.obj"));
  write_cube_features(path("cube.yml"));
  const CommandResult label =
      glint("edges label " + path("cube.obj") + " --abc-features " + path("cube.yml") + " -o " +
            path("cube.ply") + " --sampling vertices --report " + path("cube.json"));
  ASSERT_EQ(label.exit_code, 0) << label.output;
  const PointCloud cloud = io::read_ply(path("cube.ply"));
  const auto& labels = *cloud.get<std::uint8_t>("label");
  ASSERT_EQ(cloud.size(), 8u);
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    const Eigen::Vector3f p = cloud.point(i);
    // Vertices 4, 5 and 7: (0, 0, 1), (1, 0, 1), (1, 1, 1); the angles would call all 8 sharp.
    const bool on_curve = p.z() == 1 && (p.y() == 0 || p.x() == 1);
    EXPECT_EQ(labels[i], on_curve ? 1 : 0) << p.transpose();
  }
  const auto report = nlohmann::json::parse(std::ifstream(path("cube.json")));
  EXPECT_EQ(report["cloud"]["sharp_from"], "ABC features");
  EXPECT_EQ(report["cloud"]["mesh_edges"]["sharp"], 1);
  EXPECT_EQ(report["cloud"]["mesh_edges"]["smooth"], 1);
  EXPECT_DOUBLE_EQ(report["cloud"]["mesh_edges"]["sharp_length"].get<double>(), 2.0);
}

TEST_F(CliTest, LabelNamesABadFeaturesFileAndItsElementInOneLine) {
  write_cube_obj(path("cube.obj"));
  const std::vector<std::pair<std::string, std::string>> cases{
      {"curves: [\n", "line 2"},
      {"surfaces: []\n", "curves"},
      {"curves:\n- type: Line\n  vert_indices: [1]\n", "curves[0].sharp"},
      {"curves:\n- sharp: maybe\n  vert_indices: [1]\n", "curves[0].sharp"},
      {"curves:\n- sharp: true\n", "curves[0].vert_indices"},
      {"curves:\n- sharp: true\n  vert_indices: [4, 8]\n", "curves[0].vert_indices[1]"},
      {"curves:\n- sharp: true\n  vert_indices: [4, x]\n", "curves[0].vert_indices[1]"}};
  for (const auto& [text, element] : cases) {
    std::ofstream(path("bad.yml")) << text;
    const CommandResult label = glint("edges label " + path("cube.obj") + " --abc-features " +
                                      path("bad.yml") + " -o " + path("out.ply"));
    EXPECT_EQ(label.exit_code, 1) << text;
    EXPECT_NE(label.output.find("bad.yml: " + element + ":"), std::string::npos) << label.output;
    EXPECT_EQ(std::count(label.output.begin(), label.output.end(), '\n'), 1) << label.output;
    EXPECT_FALSE(fs::exists(path("out.ply")));
  }
  const CommandResult missing = glint("edges label " + path("cube.obj") + " --abc-features " +
                                      path("none.yml") + " -o " + path("out.ply"));
  EXPECT_EQ(missing.exit_code, 1);
  EXPECT_NE(missing.output.find("none.yml"), std::string::npos) << missing.output;
}

}  // namespace
}  // namespace glint
