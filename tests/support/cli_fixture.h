#pragma once
// A GoogleTest fixture that runs the glint executable (GLINT_BINARY) in a private temporary
// folder and captures its exit code and output.
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>

namespace glint {

struct CommandResult {
  int exit_code;
  std::string output;  // stdout and stderr
};

// Each test gets its own folder (ctest runs tests in parallel processes).
class CliTest : public ::testing::Test {
 protected:
  void SetUp() override {
    folder_ = std::filesystem::temp_directory_path() /
              ("glint_cli_test_" +
               std::string(::testing::UnitTest::GetInstance()->current_test_info()->name()) + "_" +
               std::to_string(::getpid()));
    std::filesystem::remove_all(folder_);
    std::filesystem::create_directories(folder_);
  }
  void TearDown() override { std::filesystem::remove_all(folder_); }

  std::string path(const std::string& name) const { return (folder_ / name).string(); }

  // glint --quiet ARGUMENTS.
  CommandResult glint(const std::string& arguments) const {
    return glint_as_given("--quiet " + arguments);
  }

  // glint ARGUMENTS, nothing added.
  CommandResult glint_as_given(const std::string& arguments) const {
    const std::string log = path("command.log");
    const std::string command = std::string(GLINT_BINARY) + " " + arguments + " > " + log + " 2>&1";
    const int status = std::system(command.c_str());
    std::ifstream stream(log);
    return {WEXITSTATUS(status), std::string(std::istreambuf_iterator<char>(stream), {})};
  }

  std::filesystem::path folder_;
};

}  // namespace glint
