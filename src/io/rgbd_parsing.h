#pragma once
// Small text-parsing helpers shared by the RGB-D sequence readers (rgbd_*.cpp).
#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <opencv2/core/mat.hpp>
#include <string>
#include <vector>

#include "io/trajectory.h"

namespace glint::io::rgbd {

// Whitespace-separated rows of a text file; blank lines and '#' comments skipped. Each row
// keeps its 1-based line number for error messages.
struct TextRow {
  int line = 0;
  std::vector<std::string> fields;
};
std::vector<TextRow> read_rows(const std::string& path);

// A number from a field; throws glint::Error(path, "line N", ...) when it is not a finite one.
double parse_number(const std::string& path, const TextRow& row, std::size_t field);

// `rows` x `columns` finite numbers read row by row from `path`, starting at row `first_row`.
Eigen::MatrixXd parse_matrix(const std::string& path, const std::vector<TextRow>& text_rows,
                             std::size_t first_row, int rows, int columns);

// A camera-to-world pose from a 4x4 matrix whose rotation block is orthonormal to 1e-2 (then
// re-orthonormalised); throws glint::Error naming `path` and `element` otherwise.
Pose pose_from_matrix(const std::string& path, const std::string& element,
                      const Eigen::Matrix4d& matrix);

// The element of `sorted` (ascending in its member `time`, seconds) nearest in time to
// `timestamp_s` within `max_difference_s` (the later one on a tie), or nullptr.
template <class Stamped>
const Stamped* nearest_in_time(const std::vector<Stamped>& sorted, double Stamped::*time,
                               double timestamp_s, double max_difference_s) {
  const auto after = std::ranges::lower_bound(sorted, timestamp_s, {}, time);
  const Stamped* best = after != sorted.end() ? &*after : nullptr;
  if (after != sorted.begin()) {
    const Stamped& before = *(after - 1);
    if (!best || timestamp_s - before.*time < best->*time - timestamp_s) best = &before;
  }
  if (!best || std::abs(best->*time - timestamp_s) > max_difference_s) return nullptr;
  return best;
}

// Decodes an image file with cv::imread `flags` (io/image_decode.h); throws glint::Error naming
// it when it is missing, truncated or unreadable.
cv::Mat decode_image(const std::string& path, int flags);

// folder / relative, as a string.
std::string join(const std::string& folder, const std::string& relative);
bool exists(const std::string& path);
// Throws glint::Error(path, "", what + " is missing") unless the file exists.
void require_file(const std::string& path, const std::string& what);

}  // namespace glint::io::rgbd
