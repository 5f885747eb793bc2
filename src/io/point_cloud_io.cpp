#include "io/point_cloud_io.h"

#include <fmt/format.h>

#include <cmath>
#include <filesystem>

#include "core/error.h"
#include "io/codec.h"
#include "io/pcd.h"
#include "io/ply.h"
#include "io/text_cloud.h"

namespace glint::io {
namespace {

std::string extension_of(const std::string& path) {
  return lowercase(std::filesystem::path(path).extension().string());
}

bool is_text_extension(const std::string& extension) {
  return extension == ".xyz" || extension == ".txt" || extension == ".pts";
}

bool is_class_label(double value) {
  return value >= 0 && value <= 255 && value == std::floor(value);
}

}  // namespace

PointCloud read_point_cloud(const std::string& path) {
  const std::string extension = extension_of(path);
  if (extension == ".ply") return read_ply(path);
  if (extension == ".pcd") return read_pcd(path);
  if (is_text_extension(extension) || extension == ".csv") return read_text_cloud(path);
  throw Error(path, "",
              fmt::format("unknown point-cloud format '{}' (supported: .ply, .xyz, .txt, .pts, "
                          ".csv, .pcd)",
                          extension));
}

void write_point_cloud(const std::string& path, const PointCloud& cloud) {
  const std::string extension = extension_of(path);
  if (extension == ".ply") return write_ply(path, cloud);
  if (is_text_extension(extension)) return write_text_cloud(path, cloud);
  throw Error(
      path, "",
      fmt::format("cannot write point-cloud format '{}' (supported: .ply, .xyz, .txt, .pts)",
                  extension));
}

std::optional<std::vector<std::uint8_t>> read_labels(const PointCloud& cloud, LabelSource source) {
  static const char* const truth_order[] = {"label", "scalar_label", "class", "scalar_class"};
  static const char* const prediction_order[] = {"scalar_label", "scalar_class", "label", "class"};
  for (const char* name : source == LabelSource::truth ? truth_order : prediction_order) {
    const AttributeColumn* column = cloud.find(name);
    if (!column) continue;
    std::vector<std::uint8_t> labels(cloud.size());
    for (std::size_t i = 0; i < cloud.size(); ++i) {
      const double value = column_value(*column, i);
      if (!is_class_label(value)) {
        throw Error("", name,
                    fmt::format("value {} at vertex {} is not a class label (whole number 0..255)",
                                value, i));
      }
      labels[i] = static_cast<std::uint8_t>(value);
    }
    return labels;
  }
  return std::nullopt;
}

}  // namespace glint::io
