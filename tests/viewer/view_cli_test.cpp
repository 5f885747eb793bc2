// `glint view` end to end: one-line errors for a folder without scene.glb and a port in use,
// --write-html's static copy from the build tree's page, and serving until SIGINT.
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include "support/cli_fixture.h"
#include "viewer/http_server.h"
#include "viewer_test_support.h"

namespace glint {
namespace {

namespace fs = std::filesystem;

class ViewCli : public CliTest {
 protected:
  void SetUp() override {
    CliTest::SetUp();
    test::write_text(folder_ / "out" / "scene.glb", "glb bytes");
  }
  // The build tree's page lacks the three.js modules where web/node_modules was not installed.
  bool page_installed() const {
    return glint("view " + path("out") + " --write-html " + path("probe")).exit_code == 0;
  }
};

TEST_F(ViewCli, FolderWithoutSceneIsOneLineError) {
  fs::create_directories(folder_ / "empty");
  const CommandResult result = glint("view " + path("empty"));
  EXPECT_EQ(result.exit_code, 1);
  EXPECT_NE(result.output.find("no scene.glb"), std::string::npos) << result.output;
  EXPECT_EQ(std::count(result.output.begin(), result.output.end(), '\n'), 1) << result.output;
  EXPECT_EQ(glint("view " + path("missing")).exit_code, 1);
}

TEST_F(ViewCli, WritesAStaticCopy) {
  if (!page_installed()) GTEST_SKIP() << "web/node_modules not installed when CMake ran";
  const CommandResult result = glint("view " + path("out") + " --write-html " + path("site"));
  ASSERT_EQ(result.exit_code, 0) << result.output;
  for (const char* file : viewer::kRequiredPageFiles)
    EXPECT_TRUE(fs::is_regular_file(fs::symlink_status(folder_ / "site" / file))) << file;
  EXPECT_TRUE(fs::exists(folder_ / "site" / "three" / "LICENSE"));
  EXPECT_EQ(fs::file_size(folder_ / "site" / "scene.glb"), 9u);
}

TEST_F(ViewCli, ServesUntilInterruptedAndRefusesAPortInUse) {
  if (!page_installed()) GTEST_SKIP() << "web/node_modules not installed when CMake ran";
  // A free port: taken by a listener of this test, so a second glint on it must fail.
  test::make_site_files(folder_ / "other");
  const viewer::StaticSite site(folder_ / "other" / "page",
                                folder_ / "other" / "out" / "scene.glb");
  viewer::ServerParams any_port;
  any_port.port = 0;
  auto holder = std::make_unique<viewer::HttpServer>(site, any_port);
  const int port = holder->port();
  const CommandResult in_use = glint("view " + path("out") + " --port " + std::to_string(port));
  EXPECT_EQ(in_use.exit_code, 1);
  EXPECT_NE(in_use.output.find("port in use"), std::string::npos) << in_use.output;
  holder.reset();  // the port is free again

  const pid_t child = fork();
  ASSERT_GE(child, 0);
  if (child == 0) {
    const std::string port_text = std::to_string(port), out = path("out");
    execl(GLINT_BINARY, GLINT_BINARY, "--quiet", "view", out.c_str(), "--port", port_text.c_str(),
          static_cast<char*>(nullptr));
    _exit(127);
  }
  std::string scene;
  for (int attempt = 0; attempt < 500 && test::body_of(scene) != "glb bytes"; ++attempt) {
    usleep(20000);
    scene = test::get(port, "/scene.glb");
  }
  EXPECT_EQ(test::body_of(scene), "glb bytes");
  EXPECT_NE(test::get(port, "/").find("importmap"), std::string::npos);  // the real page
  kill(child, SIGINT);
  int status = 0;
  ASSERT_EQ(waitpid(child, &status, 0), child);
  EXPECT_TRUE(WIFEXITED(status));
  EXPECT_EQ(WEXITSTATUS(status), 0);
}

}  // namespace
}  // namespace glint
