#include "core/error.h"

namespace glint {
namespace {

std::string compose(const std::string& file, const std::string& element,
                    const std::string& reason) {
  std::string message;
  if (!file.empty()) message += file + ": ";
  if (!element.empty()) message += element + ": ";
  return message + reason;
}

}  // namespace

Error::Error(std::string file, std::string element, std::string reason)
    : std::runtime_error(compose(file, element, reason)),
      file_(std::move(file)),
      element_(std::move(element)),
      reason_(std::move(reason)) {}

}  // namespace glint
