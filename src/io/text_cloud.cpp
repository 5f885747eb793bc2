#include "io/text_cloud.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <optional>
#include <string_view>
#include <vector>

#include "core/error.h"
#include "io/atomic_file.h"
#include "io/codec.h"
#include "io/file_bytes.h"

namespace glint::io {
namespace {

bool is_separator(char c) { return c == ' ' || c == '\t' || c == ',' || c == '\r'; }

void split(std::string_view line, std::vector<std::string_view>& tokens) {
  tokens.clear();
  std::size_t i = 0;
  while (i < line.size()) {
    while (i < line.size() && is_separator(line[i])) ++i;
    const std::size_t start = i;
    while (i < line.size() && !is_separator(line[i])) ++i;
    if (i > start) tokens.push_back(line.substr(start, i - start));
  }
}

// Removes a leading "#" or "//"; true when there was one.
bool strip_comment(std::string_view& line) {
  line.remove_prefix(std::min(line.find_first_not_of(" \t"), line.size()));
  for (const std::string_view marker : {"#", "//"}) {
    if (line.starts_with(marker)) {
      line.remove_prefix(marker.size());
      return true;
    }
  }
  return false;
}

bool is_column_header(const std::vector<std::string_view>& tokens) {
  return tokens.size() >= 3 && lowercase(tokens[0]) == "x" && lowercase(tokens[1]) == "y" &&
         lowercase(tokens[2]) == "z";
}

bool is_non_negative_whole(double value) { return value >= 0 && value == std::floor(value); }

// Larger "counts" are not counts (and would not convert to an integer exactly).
constexpr double kMaxCount = 9007199254740992.0;  // 2^53

class TextCloudReader {
 public:
  // `max_points` bounds the number of points (the number of lines), to reserve memory once.
  TextCloudReader(const std::string& path, bool point_count_line, std::size_t max_points)
      : path_(path), point_count_line_(point_count_line), max_points_(max_points) {
    for (std::vector<double>& axis : positions_) axis.reserve(max_points);
  }

  void take_line(std::string_view line, std::size_t number) {
    line_ = number;
    const bool comment = strip_comment(line);
    split(line, tokens_);
    if (tokens_.empty()) return;
    if (positions_[0].empty() && names_.empty() && is_column_header(tokens_)) {
      names_.assign(tokens_.begin(), tokens_.end());
      return;
    }
    if (comment) return;
    parse_row();
    if (is_count_line()) {
      announced_ = static_cast<std::size_t>(values_[0]);
      announced_line_ = number;
      return;
    }
    add_point();
  }

  PointCloud finish() {
    const std::size_t points = positions_[0].size();
    if (announced_ && *announced_ != points) {
      throw Error(path_, fmt::format("line {}", announced_line_),
                  fmt::format("announces {} points, the file holds {}", *announced_, points));
    }
    set_positions(cloud_, positions_[0].data(), positions_[1].data(), positions_[2].data(), points,
                  path_);
    for (std::size_t c = 0; c < extra_.size(); ++c) {
      cloud_.set(column_name(c + 3), std::move(extra_[c]));
    }
    return std::move(cloud_);
  }

 private:
  [[noreturn]] void fail(const std::string& reason) const {
    throw Error(path_, fmt::format("line {}", line_), reason);
  }

  void parse_row() {
    values_.resize(tokens_.size());
    for (std::size_t t = 0; t < tokens_.size(); ++t) {
      if (!parse_number(tokens_[t], values_[t])) {
        fail(fmt::format("not a number: '{}'", tokens_[t].substr(0, 32)));
      }
    }
  }

  // A .pts file may start with a line holding only the number of points.
  bool is_count_line() const {
    return point_count_line_ && positions_[0].empty() && !announced_ && values_.size() == 1 &&
           is_non_negative_whole(values_[0]) && values_[0] <= kMaxCount;
  }

  void add_point() {
    if (columns_ == 0) start_columns();
    if (values_.size() != columns_) {
      fail(fmt::format("expected {} columns (as on line {}), found {}", columns_, first_row_line_,
                       values_.size()));
    }
    for (std::size_t c = 0; c < columns_; ++c) {
      if (c < 3 && !std::isfinite(values_[c])) fail("non-finite coordinate");
      if (c >= 3 && !fits(Scalar::float32, values_[c])) {
        fail(fmt::format("'{}' is outside the float range", tokens_[c]));
      }
    }
    // Positions stay double until finish() re-centres them (core/point_cloud.h).
    for (int a = 0; a < 3; ++a) positions_[a].push_back(values_[a]);
    for (std::size_t c = 3; c < columns_; ++c) {
      extra_[c - 3].push_back(static_cast<float>(values_[c]));
      integral_[c - 3] = integral_[c - 3] && is_non_negative_whole(values_[c]);
    }
  }

  void start_columns() {
    if (values_.size() < 3) fail("need at least 3 columns (x y z)");
    if (!names_.empty() && names_.size() != values_.size()) {
      fail(fmt::format("the header names {} columns, the row has {}", names_.size(),
                       values_.size()));
    }
    columns_ = values_.size();
    first_row_line_ = line_;
    extra_.resize(columns_ - 3);
    for (std::vector<float>& column : extra_) column.reserve(max_points_);
    integral_.assign(columns_ - 3, true);
  }

  std::string column_name(std::size_t column) const {
    if (!names_.empty()) return names_[column];
    if (columns_ == 4 && integral_[0]) return "label";
    return fmt::format("column{}", column);
  }

  const std::string& path_;
  const bool point_count_line_;
  const std::size_t max_points_;
  std::size_t line_ = 0;  // the line being read
  std::vector<std::string_view> tokens_;
  std::vector<double> values_;
  std::vector<std::string> names_;        // from a header line
  std::optional<std::size_t> announced_;  // by a .pts count line
  std::size_t announced_line_ = 0;
  std::size_t columns_ = 0;
  std::size_t first_row_line_ = 0;
  PointCloud cloud_;
  std::vector<double> positions_[3];
  std::vector<std::vector<float>> extra_;  // the columns after x y z
  std::vector<bool> integral_;  // whether an extra column holds only non-negative whole numbers
};

void check_column_names(const std::string& path, const PointCloud& cloud) {
  for (const NamedAttribute& attribute : cloud.attributes()) {
    const std::string& name = attribute.name;
    if (name.empty() ||
        std::ranges::any_of(name, [](char c) { return is_separator(c) || c == '\n'; })) {
      throw Error(path, fmt::format("attribute '{}'", name),
                  "is not a valid column name (non-empty, no spaces or commas)");
    }
  }
}

}  // namespace

PointCloud read_text_cloud(const std::string& path) {
  const std::string bytes = read_file_bytes(path);
  const bool pts = lowercase(std::filesystem::path(path).extension().string()) == ".pts";
  TextCloudReader reader(path, pts, std::ranges::count(bytes, '\n') + 1);
  std::size_t position = 0;
  for (std::size_t number = 1; position < bytes.size(); ++number) {
    const std::size_t end = std::min(bytes.find('\n', position), bytes.size());
    reader.take_line(std::string_view(bytes).substr(position, end - position), number);
    position = end + 1;
  }
  return reader.finish();
}

void write_text_cloud(const std::string& path, const PointCloud& cloud) {
  check_column_names(path, cloud);
  AtomicFile file(path, false);
  std::string buffer = "//x y z";
  for (const NamedAttribute& attribute : cloud.attributes()) buffer += " " + attribute.name;
  buffer += '\n';
  const bool shifted = !cloud.origin.isZero();  // re-centred: write the original coordinates
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    for (int a = 0; a < 3; ++a) {
      const float value = a == 0 ? cloud.x[i] : a == 1 ? cloud.y[i] : cloud.z[i];
      if (shifted) {
        fmt::format_to(std::back_inserter(buffer), "{}", cloud.origin[a] + double(value));
      } else {
        append_value(buffer, value);
      }
      buffer += ' ';
    }
    for (const NamedAttribute& attribute : cloud.attributes()) {
      append_value(buffer, attribute.values, i);
      buffer += ' ';
    }
    buffer.back() = '\n';
    flush_buffer(buffer, file.stream());
  }
  flush_buffer(buffer, file.stream(), 0);
  file.commit();
}

}  // namespace glint::io
