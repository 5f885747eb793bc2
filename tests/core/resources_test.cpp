// Finding the models and plugins relative to the running code (core/resources.h): in the build
// tree, in a made-up installed prefix through a shared object, and through the environment.
#include "core/resources.h"

#include <dlfcn.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <cstdlib>
#include <fstream>

#include "core/build_info.h"
#include "support/error_of.h"

namespace glint {
namespace {

namespace fs = std::filesystem;

class Resources : public ::testing::Test {
 protected:
  void SetUp() override {
    for (const char* variable : {"GLINT_MODELS_DIR", "GLINT_MODELS", "GLINT_PLUGIN_DIR",
                                 "GLINT_TEST_PLUGIN", "GLINT_WEB_DIR"})
      unsetenv(variable);
    folder_ = fs::temp_directory_path() /
              ("glint_resources_test_" +
               std::string(::testing::UnitTest::GetInstance()->current_test_info()->name()) + "_" +
               std::to_string(::getpid()));
    fs::remove_all(folder_);
    fs::create_directories(folder_);
  }
  void TearDown() override {
    for (const char* variable : {"GLINT_MODELS_DIR", "GLINT_MODELS", "GLINT_PLUGIN_DIR",
                                 "GLINT_TEST_PLUGIN", "GLINT_WEB_DIR"})
      unsetenv(variable);
    fs::remove_all(folder_);
  }

  fs::path folder_;
};

constexpr PluginName kTestPlugin{"no-such-plugin.so", "GLINT_TEST_PLUGIN"};

TEST_F(Resources, PrefixesAreTheFoldersAboveTheRunningProgram) {
  const fs::path program = fs::canonical("/proc/self/exe");
  EXPECT_EQ(code_location(), program);
  const std::vector<fs::path> prefixes = candidate_prefixes();
  ASSERT_EQ(prefixes.size(), std::size_t(kMaxPrefixLevels));
  EXPECT_EQ(prefixes[0], program.parent_path().parent_path());
  EXPECT_EQ(prefixes[1], program.parent_path().parent_path().parent_path());
}

TEST_F(Resources, BuildTreeHasTheInstalledLayout) {
  // build/<preset>/tests/glint_core_tests: build/<preset>/share/glint/models is one level up.
  const fs::path models = models_directory();
  EXPECT_EQ(models, candidate_prefixes()[0] / "share" / "glint" / "models");
  EXPECT_TRUE(fs::exists(model_path("bounded-3c.json")));
  EXPECT_TRUE(fs::exists(model_path("hemicnn.json")));
  const Error missing = test::error_of([] { model_path("no-such-model.json"); });
  EXPECT_EQ(missing.file(), (models / "no-such-model.json").string());
}

TEST_F(Resources, EnvironmentOverridesTheModelsFolder) {
  setenv("GLINT_MODELS", folder_.c_str(), 1);
  EXPECT_EQ(models_directory(), folder_);
  const fs::path preferred = folder_ / "preferred";
  fs::create_directories(preferred);
  setenv("GLINT_MODELS_DIR", preferred.c_str(), 1);
  EXPECT_EQ(models_directory(), preferred);

  // A variable that names no folder is an error naming it, never a silent fallback.
  setenv("GLINT_MODELS_DIR", (folder_ / "missing").c_str(), 1);
  const Error error = test::error_of([] { models_directory(); });
  EXPECT_NE(error.file().find("$GLINT_MODELS_DIR="), std::string::npos) << error.what();
  EXPECT_NE(error.file().find("missing"), std::string::npos) << error.what();
}

TEST_F(Resources, WebFolderIsFoundInTheBuildTreeOrThroughTheEnvironment) {
  // The build tree's share/glint/web holds the page (and the three.js modules where
  // web/node_modules was installed when CMake ran).
  EXPECT_EQ(web_directory(), candidate_prefixes()[0] / "share" / "glint" / "web");
  EXPECT_TRUE(fs::exists(web_directory() / "index.html"));
  setenv("GLINT_WEB_DIR", folder_.c_str(), 1);
  EXPECT_EQ(web_directory(), folder_);
  setenv("GLINT_WEB_DIR", (folder_ / "missing").c_str(), 1);
  const Error error = test::error_of([] { web_directory(); });
  EXPECT_NE(error.file().find("$GLINT_WEB_DIR="), std::string::npos) << error.what();
}

TEST_F(Resources, PluginSearchNamesEveryPlaceAndVariable) {
  const Error error = test::error_of([] { plugin_path(kTestPlugin); });
  const std::string message = error.what();
  EXPECT_NE(message.find("GLINT_TEST_PLUGIN"), std::string::npos) << message;
  EXPECT_NE(message.find("GLINT_PLUGIN_DIR"), std::string::npos) << message;
  for (const fs::path& prefix : candidate_prefixes()) {
    const std::string searched = (prefix / "lib" / "glint" / "no-such-plugin.so").string();
    EXPECT_NE(message.find(searched), std::string::npos) << message;
  }
}

TEST_F(Resources, EnvironmentOverridesThePlugins) {
  const fs::path in_folder = folder_ / "no-such-plugin.so";
  std::ofstream(in_folder) << "not a shared object";
  setenv("GLINT_PLUGIN_DIR", folder_.c_str(), 1);
  EXPECT_EQ(plugin_path(kTestPlugin), in_folder);
  EXPECT_EQ(plugin_directory(), folder_);

  const fs::path named = folder_ / "named.so";
  setenv("GLINT_TEST_PLUGIN", named.c_str(), 1);
  EXPECT_EQ(plugin_path(kTestPlugin), named);

  // A file that is no shared object: the error names it and the variable that overrides it.
  setenv("GLINT_TEST_PLUGIN", in_folder.c_str(), 1);
  const Error error = test::error_of([] { plugin_entry(kTestPlugin, "entry"); });
  EXPECT_EQ(error.file(), in_folder.string());
  EXPECT_NE(error.reason().find("GLINT_TEST_PLUGIN"), std::string::npos) << error.what();
}

// The Python module's case: glint_core linked into a shared object installed at
// <prefix>/lib/python3/dist-packages/glint/ finds <prefix>/share/glint/models.
TEST_F(Resources, SharedObjectFindsItsOwnPrefix) {
  const fs::path prefix = folder_ / "prefix";
  const fs::path module_folder = prefix / "lib" / "python3" / "dist-packages" / "glint";
  fs::create_directories(module_folder);
  fs::create_directories(prefix / "share" / "glint" / "models");
  const fs::path module = module_folder / "probe.so";
  fs::copy_file(GLINT_RESOURCES_PROBE, module);

  void* handle = dlopen(module.c_str(), RTLD_NOW | RTLD_LOCAL);
  ASSERT_NE(handle, nullptr) << dlerror();
  using Probe = void (*)(char*, std::size_t);
  const auto probe = reinterpret_cast<Probe>(dlsym(handle, "glint_resources_probe"));
  ASSERT_NE(probe, nullptr);
  char answer[4096];
  probe(answer, sizeof answer);
  const std::string expected = fs::canonical(module).string() + "\n" +
                               fs::canonical(prefix / "share" / "glint" / "models").string();
  EXPECT_EQ(std::string(answer), expected);
}

TEST(BuildInfo, VersionReportNamesTheOptionalPartsAndTheFolders) {
  EXPECT_FALSE(build_info().version.empty());
  const std::string report = describe_build();
  EXPECT_EQ(report.rfind("glint " + build_info().version + "\n", 0), 0u) << report;
  for (const char* line : {"\nCUDA: ", "\nMPI: ", "\nmodels: ", "\nplugins: "})
    EXPECT_NE(report.find(line), std::string::npos) << report;
  EXPECT_NE(report.find(models_directory().string()), std::string::npos) << report;
}

}  // namespace
}  // namespace glint
