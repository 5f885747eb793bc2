#include "core/error.h"

#include <cmath>

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

void throw_out_of_memory(const std::string& what, double bytes) {
  const auto mebibytes = static_cast<unsigned long long>(std::ceil(bytes / (1 << 20)));
  throw Error("", what,
              "out of memory: it needs " + std::to_string(mebibytes) +
                  " MiB, more than this machine could give");
}

}  // namespace glint
