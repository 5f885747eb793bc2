#include "core/limits.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>

#include "core/error.h"

namespace glint::limits {
namespace {

std::string field(const std::string& element, const char* name) {
  return element.empty() ? name : element + "." + name;
}

}  // namespace

void check_position(const Eigen::Vector3d& position, const std::string& file,
                    const std::string& element) {
  for (int axis = 0; axis < 3; ++axis) {
    if (!(std::abs(position[axis]) <= kWorldExtentM))
      throw Error(
          file, element,
          fmt::format("coordinate {} is {} the world extent [-{:g}, {:g}] m", position[axis],
                      std::isnan(position[axis]) ? "not a number, not within" : "outside",
                      kWorldExtentM, kWorldExtentM));
  }
}

void check_image_size(std::int64_t width, std::int64_t height, const std::string& file,
                      const std::string& element) {
  if (width < 1 || height < 1 || width > kMaxImageSide || height > kMaxImageSide ||
      std::uint64_t(width) * std::uint64_t(height) > kMaxImagePixels)
    throw Error(file, element,
                fmt::format("{}x{} pixels is outside the allowed image size (each side 1 to "
                            "{}, at most {} pixels in all)",
                            width, height, kMaxImageSide, kMaxImagePixels));
}

void check_intrinsics(const Intrinsics& k, const std::string& file, const std::string& element) {
  check_image_size(k.width, k.height, file, element);
  const double focal_max = kMaxFocalPerSide * std::max(k.width, k.height);
  const auto check = [&](double value, double lowest, double highest, bool open_low,
                         const char* name) {
    const bool inside = (open_low ? value > lowest : value >= lowest) && value <= highest;
    if (!inside)
      throw Error(file, field(element, name),
                  fmt::format("{} is outside the allowed range {}{:g}, {:g}] for a {}x{} image",
                              value, open_low ? "(" : "[", lowest, highest, k.width, k.height));
  };
  check(k.fx, 0, focal_max, true, "fx");
  check(k.fy, 0, focal_max, true, "fy");
  check(k.cx, 0, k.width, false, "cx");
  check(k.cy, 0, k.height, false, "cy");
}

void throw_out_of_memory(const std::string& what, double bytes) {
  throw Error("", what,
              fmt::format("out of memory: it needs {:.0f} MiB, more than this machine could give",
                          std::ceil(bytes / (1 << 20))));
}

void check_integer(double value, double lowest, double highest, const std::string& file,
                   const std::string& element) {
  if (!(value >= lowest && value <= highest && value == std::floor(value)))
    throw Error(file, element,
                fmt::format("{} is not an integer in the allowed range [{:g}, {:g}]", value, lowest,
                            highest));
}

}  // namespace glint::limits
