#include "cli_support.h"

#include <algorithm>
#include <cstdlib>
#include <filesystem>

#include "core/error.h"
#include "core/resources.h"

namespace glint::app {
namespace {

CLI::Validator sign_check(bool zero_allowed) {
  return CLI::Validator(
      [zero_allowed](std::string& input) -> std::string {
        double value = 0;
        if (!CLI::detail::lexical_cast(input, value)) return "'" + input + "' is not a number";
        if (zero_allowed ? value >= 0 : value > 0) return {};
        return std::string(zero_allowed ? "must be 0 or more" : "must be more than 0") + ", got " +
               input;
      },
      zero_allowed ? "NONNEGATIVE" : "POSITIVE");
}

}  // namespace

const CLI::Validator kPositive = sign_check(false);
const CLI::Validator kNonNegative = sign_check(true);

const CLI::Validator kOutputFile(
    [](std::string& path) -> std::string {
      if (std::filesystem::is_directory(path)) return "'" + path + "' is a folder, not a file";
      // Missing folders are created when the file is written; one that is a file cannot be.
      for (std::filesystem::path folder = std::filesystem::path(path).parent_path();
           !folder.empty(); folder = folder.parent_path()) {
        if (std::filesystem::is_directory(folder)) break;
        if (std::filesystem::exists(folder))
          return "'" + folder.string() + "' is a file, not a folder";
      }
      return {};
    },
    "");

namespace {

bool is_point_cloud_file(const std::filesystem::path& path) {
  std::string extension = path.extension().string();
  std::transform(extension.begin(), extension.end(), extension.begin(),
                 [](unsigned char c) { return char(std::tolower(c)); });
  for (const char* known : {".ply", ".xyz", ".pts", ".txt", ".csv", ".pcd"}) {
    if (extension == known) return true;
  }
  return false;
}

}  // namespace

std::vector<std::string> expand_point_cloud_inputs(const std::vector<std::string>& paths) {
  std::vector<std::string> files;
  for (const std::string& path : paths) {
    if (std::filesystem::is_directory(path)) {
      std::vector<std::string> found;
      for (const auto& entry : std::filesystem::recursive_directory_iterator(path)) {
        if (entry.is_regular_file() && is_point_cloud_file(entry.path())) {
          found.push_back(entry.path().string());
        }
      }
      std::sort(found.begin(), found.end());
      if (found.empty()) throw Error(path, "", "folder holds no point-cloud file");
      files.insert(files.end(), found.begin(), found.end());
    } else if (std::filesystem::exists(path)) {
      files.push_back(path);
    } else {
      throw Error(path, "", "no such file or folder");
    }
  }
  return files;
}

std::string default_edges_model() { return model_path("bounded-3c.json").string(); }

namespace {
std::string recorded_command_line;
}

void remember_command_line(int argc, char** argv) {
  recorded_command_line.clear();
  for (int i = 0; i < argc; ++i) {
    if (i > 0) recorded_command_line += ' ';
    recorded_command_line += argv[i];
  }
}

const std::string& command_line() { return recorded_command_line; }

}  // namespace glint::app
