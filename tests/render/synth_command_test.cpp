// `glint synth` end to end on `cubes`, the built-in scene that needs no data folder.
#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>

#include "io/json_report.h"

namespace {
namespace fs = std::filesystem;

int run(const std::string& arguments) {
  return std::system((std::string(GLINT_BINARY) + " -q " + arguments + " 2>/dev/null").c_str());
}

TEST(SynthCommand, WritesASequenceAndAReport) {
  const fs::path out = fs::temp_directory_path() / "glint_synth_command_test";
  fs::remove_all(out);
  ASSERT_EQ(run("synth cubes --frames 2 --width 64 -o " + (out / "cubes").string() + " --report " +
                (out / "report.json").string()),
            0);
  EXPECT_TRUE(fs::exists(out / "cubes" / "rgb" / "000001.png"));
  EXPECT_TRUE(fs::exists(out / "cubes" / "gt" / "kd" / "000001.exr"));
  const nlohmann::json report = glint::io::read_json((out / "report.json").string());
  EXPECT_EQ(report["frames"], 2);
  EXPECT_EQ(report["height"], 53);  // 64 * 424 / 512
  EXPECT_GT(report["median_render_ms"].get<double>(), 0);

  ASSERT_EQ(run("synth lights --scene cubes --preview --width 64 -o " + (out / "lights").string()),
            0);
  for (const char* picture : {"rgb", "depth", "kd", "ks", "alpha"})
    EXPECT_TRUE(fs::exists(out / "lights" / (std::string(picture) + ".png"))) << picture;

  EXPECT_NE(run("synth kitchen -o " + (out / "x").string()), 0);
  fs::remove_all(out);
}

}  // namespace
