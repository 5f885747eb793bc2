#pragma once
// Helpers shared by the io tests: fixture paths, scratch files and error capture.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>

#include "core/error.h"
#include "support/error_of.h"

namespace glint::io::test {

inline std::string fixture(const std::string& name) {
  return std::string(GLINT_TEST_DATA_DIR) + "/io/" + name;
}

// The running test's own folder (tests may run in parallel processes), emptied when the test
// first asks for it.
inline std::filesystem::path scratch_folder() {
  const ::testing::TestInfo* test = ::testing::UnitTest::GetInstance()->current_test_info();
  std::string name = std::string(test->test_suite_name()) + "." + test->name();
  for (char& c : name) {
    if (c == '/') c = '_';
  }
  const auto folder = std::filesystem::temp_directory_path() / "glint_io_tests" / name;
  static std::string emptied_for;
  if (emptied_for != name) {
    std::filesystem::remove_all(folder);
    emptied_for = name;
  }
  std::filesystem::create_directories(folder);
  return folder;
}

// A path in the test's folder, with no file there yet.
inline std::string scratch(const std::string& name) {
  const auto path = scratch_folder() / name;
  std::error_code below_a_file;  // a path below a file cannot hold one either
  std::filesystem::remove(path, below_a_file);
  return path.string();
}

inline void write_text(const std::string& path, const std::string& text) {
  std::ofstream(path, std::ios::binary) << text;
}

inline std::string read_text(const std::string& path) {
  std::ifstream stream(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(stream), {}};
}

using glint::test::error_of;

}  // namespace glint::io::test
