// The glint executable end to end: synth -> train -> classify -> eval, and its error contract
// (one line naming the file, exit code 1, no output left behind).
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>

#include "io/point_cloud_io.h"
#include "support/cli_fixture.h"

namespace glint {
namespace {

namespace fs = std::filesystem;

TEST_F(CliTest, SynthTrainClassifyEval) {
  const CommandResult synth =
      glint("edges synth -o " + path("clouds") +
            " --count 4 --seed 5 --min-points 1500 --max-points 2500 --shapes box,sheet");
  ASSERT_EQ(synth.exit_code, 0) << synth.output;
  ASSERT_TRUE(fs::exists(path("clouds/manifest.json")));

  const CommandResult train =
      glint("edges train " + path("clouds") + " --iterations 30 --batch 1024 --seed 3 " +
            "--dropout 0.2 -o " + path("model.json") + " --report " + path("train.json"));
  ASSERT_EQ(train.exit_code, 0) << train.output;
  const auto model = nlohmann::json::parse(std::ifstream(path("model.json")));
  EXPECT_EQ(model["parameter_count"], 1595);
  EXPECT_EQ(model["training"]["seed"], 3);
  EXPECT_EQ(model["training"]["dropout"], 0.2);

  std::string first_cloud;
  for (const auto& entry : fs::directory_iterator(path("clouds")))
    if (entry.path().extension() == ".ply") first_cloud = entry.path().string();
  const CommandResult classify = glint("edges classify " + first_cloud + " -o " + path("out.ply") +
                                       " --model " + path("model.json") + " --png " +
                                       path("out.png") + " --report " + path("classify.json"));
  ASSERT_EQ(classify.exit_code, 0) << classify.output;
  const PointCloud out = io::read_point_cloud(path("out.ply"));
  EXPECT_TRUE(out.get<std::uint8_t>("scalar_label"));
  EXPECT_TRUE(out.get<float>("scalar_p_sharp"));
  EXPECT_TRUE(out.get<float>("scalar_p_boundary"));
  EXPECT_TRUE(out.get<std::uint8_t>("red"));
  EXPECT_TRUE(out.get<std::uint8_t>("label"));  // the input's own properties are kept
  EXPECT_GT(fs::file_size(path("out.png")), 0u);

  // --pred on the classify output scores its scalar_label, not the input's label it keeps.
  const CommandResult scored =
      glint("edges eval " + first_cloud + " --pred " + path("out.ply") + " --model " +
            path("model.json") + " --no-baseline --report " + path("pred.json"));
  ASSERT_EQ(scored.exit_code, 0) << scored.output;
  const auto pred = nlohmann::json::parse(std::ifstream(path("pred.json")));
  const auto& scores = pred["files"][0]["scores"];
  EXPECT_EQ(scores["predictions"]["tp"], scores["glint:model"]["tp"]);
  EXPECT_EQ(scores["predictions"]["fp"], scores["glint:model"]["fp"]);

  // A model with the angular gap: 13 inputs per scale, 2 x 2 x 12 more weights in the first
  // fusion level; eval scores it beside the first, each on its own features.
  const CommandResult gap_train =
      glint("edges train " + path("clouds") + " --iterations 30 --batch 1024 --seed 3 " +
            "--angular-gap -o " + path("gap.json"));
  ASSERT_EQ(gap_train.exit_code, 0) << gap_train.output;
  const auto gap_model = nlohmann::json::parse(std::ifstream(path("gap.json")));
  EXPECT_EQ(gap_model["parameter_count"], 1595 + 48);
  EXPECT_EQ(gap_model["features_per_scale"], 13);

  const CommandResult eval =
      glint("edges eval " + path("clouds") + " --model " + path("model.json") + " --model " +
            path("gap.json") + " --report " + path("eval.json"));
  ASSERT_EQ(eval.exit_code, 0) << eval.output;
  EXPECT_NE(eval.output.find("median"), std::string::npos) << eval.output;
  const auto report = nlohmann::json::parse(std::ifstream(path("eval.json")));
  EXPECT_EQ(report["files"].size(), 4u);
  EXPECT_TRUE(report["files"][0]["scores"].contains("glint:gap"));
  EXPECT_TRUE(report["files"][0]["scores"].contains("glint:model"));
}

TEST_F(CliTest, AngleGapBaselineInEvalAndClassify) {
  const CommandResult synth = glint("edges synth -o " + path("sheets") +
                                    " --count 1 --seed 9 --min-points 2000 --max-points 2000 "
                                    "--shapes sheet");
  ASSERT_EQ(synth.exit_code, 0) << synth.output;
  std::string sheet;
  for (const auto& entry : fs::directory_iterator(path("sheets")))
    if (entry.path().extension() == ".ply") sheet = entry.path().string();

  // The boundary task scores the angle-gap column beside CA; the sharp task has none.
  const CommandResult boundary = glint("edges eval " + sheet + " --pred " + sheet +
                                       " --task boundary --report " + path("boundary.json"));
  ASSERT_EQ(boundary.exit_code, 0) << boundary.output;
  const auto report = nlohmann::json::parse(std::ifstream(path("boundary.json")));
  EXPECT_TRUE(report["summary"].contains("angle-gap"));
  EXPECT_GT(report["summary"]["angle-gap"]["median"]["recall"].get<double>(), 0.0);
  EXPECT_EQ(report["angle_gap_baseline"]["radius_spacings"], 1.5);
  EXPECT_TRUE(report["files_without_positives"].empty());
  const CommandResult sharp =
      glint("edges eval " + sheet + " --pred " + sheet + " --report " + path("sharp.json"));
  ASSERT_EQ(sharp.exit_code, 0) << sharp.output;
  const auto sharp_report = nlohmann::json::parse(std::ifstream(path("sharp.json")));
  EXPECT_FALSE(sharp_report["summary"].contains("angle-gap"));
  // A sheet has no sharp edge: its MCC is undefined, and eval says so rather than let the 0 pass
  // for a score.
  EXPECT_EQ(sharp_report["files_without_positives"].size(), 1u);
  EXPECT_NE(sharp.output.find("1 of 1 files have no sharp point"), std::string::npos)
      << sharp.output;

  const CommandResult classify =
      glint("edges classify " + sheet + " -o " + path("gap.ply") + " --method angle-gap");
  ASSERT_EQ(classify.exit_code, 0) << classify.output;
  const PointCloud gap = io::read_point_cloud(path("gap.ply"));
  const auto* labels = gap.get<std::uint8_t>("scalar_label");
  ASSERT_TRUE(labels);
  EXPECT_GT(std::count(labels->begin(), labels->end(), 2), 0);
  EXPECT_EQ(std::count(labels->begin(), labels->end(), 1), 0);
}

TEST_F(CliTest, BadInputsGiveOneLineAndNoOutput) {
  const std::string truncated = path("truncated.ply");
  std::ofstream(truncated) << "ply\nformat binary_little_endian 1.0\nelement vertex 500\n"
                              "property float x\nproperty float y\nproperty float z\nend_header\n"
                           << std::string(100, '\0');
  CommandResult run = glint("edges classify " + truncated + " -o " + path("never.ply"));
  EXPECT_EQ(run.exit_code, 1);
  EXPECT_NE(run.output.find("truncated.ply"), std::string::npos) << run.output;
  EXPECT_NE(run.output.find("truncated"), std::string::npos) << run.output;
  EXPECT_FALSE(fs::exists(path("never.ply")));

  const std::string tiny = path("tiny.xyz");
  std::ofstream(tiny) << "0 0 0\n1 0 0\n0 1 0\n";
  run = glint("edges classify " + tiny + " -o " + path("never.ply"));
  EXPECT_EQ(run.exit_code, 1);
  EXPECT_NE(run.output.find("tiny.xyz"), std::string::npos) << run.output;
  EXPECT_FALSE(fs::exists(path("never.ply")));

  run = glint("edges classify " + path("missing.ply") + " -o " + path("never.ply"));
  EXPECT_EQ(run.exit_code, 1);
  run = glint("edges classify " + tiny + " -o " + path("never.ply") + " --model " + truncated);
  EXPECT_EQ(run.exit_code, 1);
  EXPECT_NE(run.output.find("truncated.ply"), std::string::npos) << run.output;
}

TEST_F(CliTest, GateJoinsTwoNetworksAndClassifyReportsItsChoice) {
  const std::string models = std::string(GLINT_TEST_DATA_DIR) + "/../../models/";
  const std::string three = models + "bounded-3c.json", two = models + "bounded-2c.json";
  CommandResult run =
      glint("edges gate " + two + " " + three + " --threshold 0.1 -o " + path("never.json"));
  EXPECT_EQ(run.exit_code, 1);
  EXPECT_NE(run.output.find("bounded-3c.json"), std::string::npos) << run.output;
  EXPECT_EQ(std::count(run.output.begin(), run.output.end(), '\n'), 1) << run.output;
  run = glint("edges gate " + two + " " + two + " --threshold 0 -o " + path("never.json"));
  EXPECT_EQ(run.exit_code, 1);
  EXPECT_NE(run.output.find("--threshold"), std::string::npos) << run.output;
  run = glint("edges gate " + two + " " + two + " --statistic density --threshold 1 -o " +
              path("never.json"));
  EXPECT_EQ(run.exit_code, 1);
  EXPECT_NE(run.output.find("--statistic"), std::string::npos) << run.output;
  EXPECT_FALSE(fs::exists(path("never.json")));

  run = glint("edges gate " + two + " " + two + " --threshold 0.1 -o " + path("gated.json"));
  ASSERT_EQ(run.exit_code, 0) << run.output;
  // The shipped 3-class model already has its sampling gate.
  for (const std::string& gated : {path("gated.json"), three}) {
    run = glint("edges gate " + gated + " " + two + " --threshold 0.1 -o " + path("never.json"));
    EXPECT_EQ(run.exit_code, 1);
    EXPECT_NE(run.output.find("already has a gate"), std::string::npos) << run.output;
  }

  run = glint("edges synth -o " + path("clouds") +
              " --count 1 --seed 5 --min-points 1500 --max-points 2500 --shapes box --noise 0 "
              "--outliers 0");
  ASSERT_EQ(run.exit_code, 0) << run.output;
  std::string cloud;
  for (const auto& entry : fs::directory_iterator(path("clouds")))
    if (entry.path().extension() == ".ply") cloud = entry.path().string();
  run = glint("edges classify " + cloud + " -o " + path("out.ply") + " --model " +
              path("gated.json") + " --report " + path("classify.json"));
  ASSERT_EQ(run.exit_code, 0) << run.output;
  const auto report = nlohmann::json::parse(std::ifstream(path("classify.json")));
  EXPECT_EQ(report["gate"]["kind"], "noise") << report.dump();
  EXPECT_EQ(report["gate"]["network"], "low-noise") << report.dump();
  EXPECT_EQ(report["gate"]["threshold"], 0.1f);

  // The shipped 3-class model's sampling gate keeps an even sample on its default network.
  run = glint("edges classify " + cloud + " -o " + path("out.ply") + " --model " + three +
              " --report " + path("classify.json"));
  ASSERT_EQ(run.exit_code, 0) << run.output;
  const auto shipped = nlohmann::json::parse(std::ifstream(path("classify.json")));
  EXPECT_EQ(shipped["gate"]["kind"], "sampling") << shipped.dump();
  EXPECT_EQ(shipped["gate"]["network"], "default") << shipped.dump();
  run = glint("edges classify " + cloud + " -o " + path("out.ply") + " --model " + three +
              " --no-gate --report " + path("classify.json"));
  ASSERT_EQ(run.exit_code, 0) << run.output;
  EXPECT_TRUE(nlohmann::json::parse(std::ifstream(path("classify.json")))["gate"].is_null());
}

// --png into a missing folder failed after OUT.ply was written, leaving it behind; now the
// folder is made, and a --png that cannot be written is refused before anything is.
TEST_F(CliTest, ClassifyWritesBothOutputsOrNeither) {
  const std::string cloud = path("cube.xyz");
  {
    std::ofstream out(cloud);
    for (int i = 0; i < 600; ++i)
      out << (i % 10) * 0.1 << " " << (i / 10 % 10) * 0.1 << " " << (i / 100) * 0.1 << "\n";
  }
  CommandResult run = glint("edges classify " + cloud + " -o " + path("out.ply") + " --png " +
                            path("pictures/new/out.png"));
  EXPECT_EQ(run.exit_code, 0) << run.output;
  EXPECT_TRUE(fs::exists(path("out.ply")));
  EXPECT_TRUE(fs::exists(path("pictures/new/out.png")));

  std::ofstream(path("a-file")) << "not a folder";
  run = glint("edges classify " + cloud + " -o " + path("never.ply") + " --png " +
              path("a-file/out.png"));
  EXPECT_NE(run.exit_code, 0);
  EXPECT_NE(run.output.find("is a file, not a folder"), std::string::npos) << run.output;
  EXPECT_FALSE(fs::exists(path("never.ply")));
}

TEST_F(CliTest, HelpOnEveryLevel) {
  for (const char* command : {"", "edges", "edges classify", "edges train", "edges synth",
                              "edges eval", "edges features"}) {
    const CommandResult run = glint(std::string(command) + " --help");
    EXPECT_EQ(run.exit_code, 0) << command;
    EXPECT_NE(run.output.find("Usage"), std::string::npos) << command;
  }
}

}  // namespace
}  // namespace glint
