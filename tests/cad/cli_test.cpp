// `glint edges synth --kind cad` and `glint edges label` end to end, and a bad STEP file's
// one-line error.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>

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
}

TEST_F(CliTest, LabelNamesABadStepFileInOneLine) {
  std::ofstream(path("bad.step")) << "ISO-10303-21;\nHEADER;\nFILE_DESCRIPTION((";
  const CommandResult label = glint("edges label " + path("bad.step") + " -o " + path("out.ply"));
  EXPECT_EQ(label.exit_code, 1);
  EXPECT_NE(label.output.find("bad.step"), std::string::npos) << label.output;
  EXPECT_EQ(std::count(label.output.begin(), label.output.end(), '\n'), 1) << label.output;
  EXPECT_FALSE(fs::exists(path("out.ply")));
}

}  // namespace
}  // namespace glint
