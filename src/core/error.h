#pragma once
// glint::Error: the one exception type at glint's API boundaries.
// It names the file (or other input) that was wrong, the element inside it (a line, a vertex,
// a property, a pixel; may be empty) and the reason, so the CLI can print one clear line.
#include <stdexcept>
#include <string>

namespace glint {

class Error : public std::runtime_error {
 public:
  Error(std::string file, std::string element, std::string reason);

  const std::string& file() const noexcept { return file_; }
  const std::string& element() const noexcept { return element_; }
  const std::string& reason() const noexcept { return reason_; }

 private:
  std::string file_;
  std::string element_;
  std::string reason_;
};

}  // namespace glint
