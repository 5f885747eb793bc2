#include "io/point_cloud_io.h"

#include <fmt/format.h>

#include <cmath>
#include <filesystem>

#include "core/error.h"
#include "io/pcd.h"
#include "io/ply.h"
#include "io/text_cloud.h"

namespace glint::io {
namespace {

std::string lower_extension(const std::string& path) {
  std::string extension = std::filesystem::path(path).extension().string();
  for (char& c : extension) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return extension;
}

bool is_text_extension(const std::string& e) { return e == ".xyz" || e == ".txt" || e == ".pts"; }

}  // namespace

PointCloud read_point_cloud(const std::string& path) {
  const std::string extension = lower_extension(path);
  if (extension == ".ply") return read_ply(path);
  if (extension == ".pcd") return read_pcd(path);
  if (is_text_extension(extension) || extension == ".csv") return read_text_cloud(path);
  throw Error(path, "", "unknown point-cloud format '" + extension +
                            "' (supported: .ply, .xyz, .txt, .pts, .csv, .pcd)");
}

void write_point_cloud(const std::string& path, const PointCloud& cloud) {
  const std::string extension = lower_extension(path);
  if (extension == ".ply") return write_ply(path, cloud);
  if (is_text_extension(extension)) return write_text_cloud(path, cloud);
  throw Error(path, "", "cannot write '" + extension + "' (supported: .ply, .xyz, .txt, .pts)");
}

std::optional<std::vector<std::uint8_t>> read_labels(const PointCloud& cloud) {
  for (const char* name : {"label", "scalar_label", "class", "scalar_class"}) {
    const AttributeColumn* column = cloud.find(name);
    if (!column) continue;
    std::vector<std::uint8_t> labels(cloud.size());
    for (std::size_t i = 0; i < cloud.size(); ++i) {
      const double value = column_value(*column, i);
      if (!(value >= 0 && value <= 255 && value == std::floor(value)))
        throw Error("", name, fmt::format("value {} at vertex {} is not a class label (whole number 0..255)", value, i));
      labels[i] = static_cast<std::uint8_t>(value);
    }
    return labels;
  }
  return std::nullopt;
}

}  // namespace glint::io
