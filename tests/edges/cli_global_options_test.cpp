// glint's global options (--quiet, --threads, --log-level) before, between and after the
// subcommands, and glint --version.
#include <gtest/gtest.h>

#include <filesystem>

#include "core/build_info.h"
#include "support/cli_fixture.h"

namespace glint {
namespace {

namespace fs = std::filesystem;

class GlobalOptions : public CliTest {
 protected:
  void SetUp() override {
    CliTest::SetUp();
    const CommandResult synth = glint("edges synth -o " + path("clouds") +
                                      " --count 1 --seed 2 --min-points 1500 --max-points 2000 "
                                      "--shapes box");
    ASSERT_EQ(synth.exit_code, 0) << synth.output;
    for (const auto& entry : fs::directory_iterator(path("clouds")))
      if (entry.path().extension() == ".ply") cloud_ = entry.path().string();
    ASSERT_FALSE(cloud_.empty());
  }

  std::string classify() const { return "edges classify " + cloud_ + " -o " + path("out.ply"); }

  std::string cloud_;
};

// classify logs the model it uses at level info; --log-level warn hides that line.
constexpr const char* kInfoLine = "[info]";

TEST_F(GlobalOptions, AcceptedBeforeTheCommand) {
  const CommandResult run = glint_as_given("--quiet --threads 1 --log-level warn " + classify());
  ASSERT_EQ(run.exit_code, 0) << run.output;
  EXPECT_EQ(run.output.find(kInfoLine), std::string::npos) << run.output;
}

TEST_F(GlobalOptions, AcceptedAfterTheCommand) {
  const CommandResult quiet = glint_as_given(classify() + " --quiet");
  ASSERT_EQ(quiet.exit_code, 0) << quiet.output;
  EXPECT_NE(quiet.output.find(kInfoLine), std::string::npos) << quiet.output;
  EXPECT_TRUE(fs::exists(path("out.ply")));

  const CommandResult all = glint_as_given(classify() + " -q --threads 1 --log-level warn");
  ASSERT_EQ(all.exit_code, 0) << all.output;
  EXPECT_EQ(all.output.find(kInfoLine), std::string::npos) << all.output;
}

TEST_F(GlobalOptions, AcceptedBetweenTheCommands) {
  const CommandResult run = glint_as_given("edges --log-level warn classify " + cloud_ + " -q -o " +
                                           path("out.ply") + " --threads 2");
  ASSERT_EQ(run.exit_code, 0) << run.output;
  EXPECT_EQ(run.output.find(kInfoLine), std::string::npos) << run.output;
}

TEST_F(GlobalOptions, CheckedWhereverTheyStand) {
  const CommandResult negative = glint_as_given(classify() + " --threads -1");
  EXPECT_NE(negative.exit_code, 0);
  EXPECT_NE(negative.output.find("--threads"), std::string::npos) << negative.output;
  EXPECT_FALSE(fs::exists(path("out.ply")));

  const CommandResult level = glint_as_given(classify() + " --log-level loud");
  EXPECT_EQ(level.exit_code, 1);
  EXPECT_NE(level.output.find("loud"), std::string::npos) << level.output;

  // An option no level knows is still refused.
  const CommandResult unknown = glint_as_given(classify() + " --no-such-option");
  EXPECT_NE(unknown.exit_code, 0);
  EXPECT_NE(unknown.output.find("--no-such-option"), std::string::npos) << unknown.output;
}

TEST_F(CliTest, VersionSaysWhatIsCompiledInAndWhereFilesAre) {
  const CommandResult run = glint_as_given("--version");
  ASSERT_EQ(run.exit_code, 0) << run.output;
  EXPECT_EQ(run.output.rfind("glint " + build_info().version + "\n", 0), 0u) << run.output;
  EXPECT_NE(run.output.find(build_info().cuda ? "CUDA: compiled in" : "CUDA: not compiled in"),
            std::string::npos)
      << run.output;
  EXPECT_NE(run.output.find("\nMPI: "), std::string::npos) << run.output;
  // The build tree's layout: build/<preset>/share/glint/models and build/<preset>/lib/glint.
  const fs::path build = fs::path(GLINT_BINARY).parent_path().parent_path().parent_path();
  EXPECT_NE(run.output.find("models: " + (build / "share/glint/models").string()),
            std::string::npos)
      << run.output;
  EXPECT_NE(run.output.find("plugins: " + (build / "lib/glint").string()), std::string::npos)
      << run.output;
}

}  // namespace
}  // namespace glint
