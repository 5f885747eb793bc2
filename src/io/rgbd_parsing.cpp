#include "io/rgbd_parsing.h"

#include <fmt/format.h>

#include <Eigen/SVD>
#include <cmath>
#include <filesystem>
#include <sstream>

#include "core/error.h"
#include "core/limits.h"
#include "io/file_bytes.h"
#include "io/image_decode.h"

namespace glint::io::rgbd {

std::vector<TextRow> read_rows(const std::string& path) {
  std::istringstream text(read_file_bytes(path));
  std::vector<TextRow> rows;
  std::string line;
  for (int line_number = 1; std::getline(text, line); ++line_number) {
    const auto first = line.find_first_not_of(" \t\r");
    if (first == std::string::npos || line[first] == '#') continue;
    TextRow row{line_number, {}};
    std::istringstream fields(line);
    for (std::string field; fields >> field;) row.fields.push_back(field);
    rows.push_back(std::move(row));
  }
  return rows;
}

double parse_number(const std::string& path, const TextRow& row, std::size_t field) {
  const std::string element = "line " + std::to_string(row.line);
  if (field >= row.fields.size())
    throw Error(path, element, fmt::format("expected at least {} fields", field + 1));
  double value = 0;
  std::size_t used = 0;
  try {
    value = std::stod(row.fields[field], &used);
  } catch (const std::exception&) {
    used = 0;
  }
  if (used != row.fields[field].size() || !std::isfinite(value))
    throw Error(path, element, fmt::format("'{}' is not a finite number", row.fields[field]));
  return value;
}

Eigen::MatrixXd parse_matrix(const std::string& path, const std::vector<TextRow>& text_rows,
                             std::size_t first_row, int rows, int columns) {
  if (first_row + rows > text_rows.size())
    throw Error(path, "",
                fmt::format("expected a {}x{} matrix, the file ends early", rows, columns));
  Eigen::MatrixXd matrix(rows, columns);
  for (int r = 0; r < rows; ++r) {
    const TextRow& row = text_rows[first_row + r];
    if (row.fields.size() != static_cast<std::size_t>(columns))
      throw Error(path, "line " + std::to_string(row.line),
                  fmt::format("expected {} numbers in a matrix row", columns));
    for (int c = 0; c < columns; ++c) matrix(r, c) = parse_number(path, row, c);
  }
  return matrix;
}

Pose pose_from_matrix(const std::string& path, const std::string& element,
                      const Eigen::Matrix4d& matrix) {
  const Eigen::Matrix3d rotation = matrix.topLeftCorner<3, 3>();
  const double error = (rotation.transpose() * rotation - Eigen::Matrix3d::Identity()).norm();
  if (error > 1e-2 || rotation.determinant() <= 0 ||
      (matrix.row(3) - Eigen::RowVector4d(0, 0, 0, 1)).norm() > 1e-6)
    throw Error(path, element,
                "not a rigid 4x4 transform (rotation not orthonormal or last row not 0 0 0 1)");
  const Eigen::JacobiSVD<Eigen::Matrix3d> svd(rotation, Eigen::ComputeFullU | Eigen::ComputeFullV);
  Pose pose = Pose::Identity();
  pose.linear() = svd.matrixU() * svd.matrixV().transpose();
  pose.translation() = matrix.topRightCorner<3, 1>();
  limits::check_position(pose.translation(), path, element.empty() ? "translation" : element);
  return pose;
}

cv::Mat decode_image(const std::string& path, int flags) {
  require_file(path, "the image");
  return decode_image_file(path, flags);
}

std::string join(const std::string& folder, const std::string& relative) {
  return (std::filesystem::path(folder) / relative).string();
}

bool exists(const std::string& path) { return std::filesystem::exists(path); }

void require_file(const std::string& path, const std::string& what) {
  if (!std::filesystem::is_regular_file(path)) throw Error(path, "", what + " is missing");
}

}  // namespace glint::io::rgbd
