#pragma once
// Helpers shared by the io tests: fixture paths and scratch files.
#include <filesystem>
#include <fstream>
#include <string>

namespace glint::io::test {

inline std::string fixture(const std::string& name) {
  return std::string(GLINT_TEST_DATA_DIR) + "/io/" + name;
}

// A fresh path in the test's temporary folder.
inline std::string scratch(const std::string& name) {
  const auto folder = std::filesystem::temp_directory_path() / "glint_io_tests";
  std::filesystem::create_directories(folder);
  const auto path = folder / name;
  std::filesystem::remove(path);
  return path.string();
}

inline void write_text(const std::string& path, const std::string& text) {
  std::ofstream(path, std::ios::binary) << text;
}

inline std::string read_text(const std::string& path) {
  std::ifstream stream(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(stream), {}};
}

}  // namespace glint::io::test
