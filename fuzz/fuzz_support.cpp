#include "fuzz_support.h"

#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <system_error>

namespace glint::fuzz {
namespace {

class ScratchFolder {
 public:
  ScratchFolder()
      : path_(
            (std::filesystem::temp_directory_path() / ("glint-fuzz-" + std::to_string(::getpid())))
                .string()) {
    std::filesystem::create_directories(path_);
  }
  ~ScratchFolder() {
    std::error_code ignored;
    std::filesystem::remove_all(path_, ignored);
  }
  const std::string& path() const { return path_; }

 private:
  std::string path_;
};

}  // namespace

const std::string& scratch_folder() {
  static const ScratchFolder folder;
  return folder.path();
}

std::string write_scratch_file(const std::string& name, std::string_view data) {
  const std::string path = scratch_folder() + "/" + name;
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out.write(data.data(), static_cast<std::streamsize>(data.size()));
  out.close();
  if (!out) throw std::runtime_error("fuzz: cannot write " + path + ": " + std::strerror(errno));
  return path;
}

std::vector<std::string_view> split_sections(std::string_view data, std::size_t count) {
  constexpr std::string_view kSeparator = "\n====\n";
  std::vector<std::string_view> sections;
  while (sections.size() + 1 < count) {
    const std::size_t at = data.find(kSeparator);
    if (at == std::string_view::npos) break;
    sections.push_back(data.substr(0, at + 1));  // keeps the section's last newline
    data.remove_prefix(at + kSeparator.size());
  }
  sections.push_back(data);
  sections.resize(count);
  return sections;
}

}  // namespace glint::fuzz
