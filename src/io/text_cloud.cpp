#include "io/text_cloud.h"

#include <fmt/format.h>

#include <charconv>
#include <cmath>
#include <filesystem>

#include "core/error.h"
#include "io/atomic_file.h"
#include "io/file_bytes.h"

namespace glint::io {
namespace {

bool is_separator(char c) { return c == ' ' || c == '\t' || c == ',' || c == ';' || c == '\r'; }

// Splits a line into tokens at spaces, tabs, commas and semicolons.
std::vector<std::string_view> tokens_of(std::string_view line) {
  std::vector<std::string_view> tokens;
  std::size_t i = 0;
  while (i < line.size()) {
    while (i < line.size() && is_separator(line[i])) ++i;
    const std::size_t start = i;
    while (i < line.size() && !is_separator(line[i])) ++i;
    if (i > start) tokens.push_back(line.substr(start, i - start));
  }
  return tokens;
}

bool parse_number(std::string_view token, double& value) {
  const auto [end, ec] = std::from_chars(token.data(), token.data() + token.size(), value);
  return ec == std::errc() && end == token.data() + token.size();
}

std::string lower(std::string_view text) {
  std::string result(text);
  for (char& c : result) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return result;
}

}  // namespace

PointCloud read_text_cloud(const std::string& path) {
  const std::string bytes = read_file_bytes(path);
  const bool pts = lower(std::filesystem::path(path).extension().string()) == ".pts";
  std::vector<std::string> names;        // from a header line, when there is one
  std::vector<std::vector<float>> extra;  // columns after x y z
  std::vector<bool> extra_integral;
  PointCloud cloud;
  std::size_t columns = 0;
  long long announced = -1;
  std::vector<double> values;

  std::size_t position = 0;
  for (std::size_t line_number = 1; position < bytes.size(); ++line_number) {
    std::size_t end = bytes.find('\n', position);
    if (end == std::string::npos) end = bytes.size();
    std::string_view line(bytes.data() + position, end - position);
    position = end + 1;
    const std::string where = fmt::format("line {}", line_number);
    const std::size_t first = line.find_first_not_of(" \t\r");
    if (first == std::string_view::npos) continue;
    line.remove_prefix(first);
    const bool comment = line.rfind("#", 0) == 0 || line.rfind("//", 0) == 0;
    if (comment) line.remove_prefix(line[0] == '#' ? 1 : 2);
    const std::vector<std::string_view> tokens = tokens_of(line);
    if (tokens.empty()) continue;

    values.resize(tokens.size());
    bool numeric = true;
    for (std::size_t t = 0; t < tokens.size() && numeric; ++t) numeric = parse_number(tokens[t], values[t]);
    if (comment || !numeric) {
      // A header naming the columns ("//X Y Z label", "x,y,z,intensity") before any point.
      if (cloud.empty() && names.empty() && tokens.size() >= 3 && lower(tokens[0]) == "x" &&
          lower(tokens[1]) == "y" && lower(tokens[2]) == "z") {
        for (const auto& token : tokens) names.push_back(lower(token));
        continue;
      }
      if (comment) continue;
      throw Error(path, where, "not a number in '" + std::string(line.substr(0, 60)) + "'");
    }
    if (pts && cloud.empty() && announced < 0 && tokens.size() == 1 && values[0] >= 0 &&
        values[0] == std::floor(values[0])) {
      announced = static_cast<long long>(values[0]);  // the point count line of a .pts file
      continue;
    }
    if (columns == 0) {
      if (tokens.size() < 3) throw Error(path, where, "need at least 3 columns (x y z)");
      if (!names.empty() && names.size() != tokens.size())
        throw Error(path, where, fmt::format("the header names {} columns, the row has {}", names.size(), tokens.size()));
      columns = tokens.size();
      extra.resize(columns - 3);
      extra_integral.assign(columns - 3, true);
    } else if (tokens.size() != columns) {
      throw Error(path, where, fmt::format("expected {} columns as on the first row, found {}", columns, tokens.size()));
    }
    for (int a = 0; a < 3; ++a)
      if (!std::isfinite(values[a])) throw Error(path, where, "non-finite coordinate");
    cloud.push_back(float(values[0]), float(values[1]), float(values[2]));
    for (std::size_t c = 3; c < columns; ++c) {
      extra[c - 3].push_back(float(values[c]));
      extra_integral[c - 3] = extra_integral[c - 3] && values[c] == std::floor(values[c]);
    }
  }
  if (announced >= 0 && static_cast<std::size_t>(announced) != cloud.size())
    throw Error(path, "line 1", fmt::format("announces {} points, the file holds {}", announced, cloud.size()));
  if (cloud.empty()) throw Error(path, "", "no points");
  for (std::size_t c = 0; c < extra.size(); ++c) {
    std::string name = names.empty() ? fmt::format("column{}", c + 3) : names[c + 3];
    if (names.empty() && extra.size() == 1 && extra_integral[0]) name = "label";
    cloud.set(name, std::move(extra[c]));
  }
  return cloud;
}

void write_text_cloud(const std::string& path, const PointCloud& cloud) {
  std::string out = "//x y z";
  for (const NamedAttribute& attribute : cloud.attributes()) out += " " + attribute.name;
  out += '\n';
  char buffer[64];
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    for (const float value : {cloud.x[i], cloud.y[i], cloud.z[i]}) {
      out.append(buffer, std::to_chars(buffer, buffer + sizeof buffer, value).ptr);
      out += ' ';
    }
    for (const NamedAttribute& attribute : cloud.attributes()) {
      out.append(buffer, std::to_chars(buffer, buffer + sizeof buffer, column_value(attribute.values, i)).ptr);
      out += ' ';
    }
    out.back() = '\n';
  }
  AtomicFile file(path, false);
  file.stream() << out;
  file.commit();
}

}  // namespace glint::io
