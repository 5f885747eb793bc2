#include "io/pcd.h"

#include <fmt/format.h>

#include <charconv>
#include <cmath>
#include <cstring>
#include <sstream>

#include "core/error.h"
#include "io/file_bytes.h"

namespace glint::io {
namespace {

struct Field {
  std::string name;
  int size = 4;
  char type = 'F';  // I signed, U unsigned, F float
  int count = 1;
};

AttributeColumn column_for(const Field& field, std::size_t n) {
  if (field.type == 'F') return field.size == 8 ? AttributeColumn(std::vector<double>(n)) : std::vector<float>(n);
  const bool is_signed = field.type == 'I';
  switch (field.size) {
    case 1: return is_signed ? AttributeColumn(std::vector<std::int8_t>(n)) : std::vector<std::uint8_t>(n);
    case 2: return is_signed ? AttributeColumn(std::vector<std::int16_t>(n)) : std::vector<std::uint16_t>(n);
    default: return is_signed ? AttributeColumn(std::vector<std::int32_t>(n)) : std::vector<std::uint32_t>(n);
  }
}

void store(AttributeColumn& column, std::size_t i, double value) {
  std::visit([&](auto& values) { values[i] = static_cast<typename std::decay_t<decltype(values)>::value_type>(value); },
             column);
}

// A binary field value (PCL writes little-endian) as double; the raw 32 bits for packed rgb.
double decode(const Field& field, const char* at) {
  auto read = [at](auto value) {
    std::memcpy(&value, at, sizeof value);
    return static_cast<double>(value);
  };
  if (field.type == 'F') return field.size == 8 ? read(double{}) : read(float{});
  const bool s = field.type == 'I';
  switch (field.size) {
    case 1: return s ? read(std::int8_t{}) : read(std::uint8_t{});
    case 2: return s ? read(std::int16_t{}) : read(std::uint16_t{});
    case 8: return s ? read(std::int64_t{}) : read(std::uint64_t{});
    default: return s ? read(std::int32_t{}) : read(std::uint32_t{});
  }
}

bool is_rgb(const Field& f) { return (f.name == "rgb" || f.name == "rgba") && f.size == 4 && f.count == 1; }

}  // namespace

PointCloud read_pcd(const std::string& path) {
  const std::string bytes = read_file_bytes(path);
  std::vector<Field> fields;
  std::size_t points = 0, position = 0;
  bool has_points = false;
  std::string data;
  for (int line_number = 1; data.empty(); ++line_number) {
    const std::size_t end = bytes.find('\n', position);
    if (end == std::string::npos) throw Error(path, "header", "no DATA line (not a PCD file?)");
    std::istringstream line(bytes.substr(position, end - position));
    position = end + 1;
    const std::string where = fmt::format("header line {}", line_number);
    std::string key;
    if (!(line >> key) || key[0] == '#') continue;
    std::vector<std::string> words;
    for (std::string word; line >> word;) words.push_back(word);
    auto integers = [&](std::vector<int>& out) {
      for (const std::string& w : words) {
        int value = 0;
        if (std::from_chars(w.data(), w.data() + w.size(), value).ec != std::errc() || value < 1)
          throw Error(path, where, key + ": '" + w + "' is not a positive integer");
        out.push_back(value);
      }
      if (out.size() != fields.size()) throw Error(path, where, key + " must have one entry per field");
    };
    if (key == "VERSION" || key == "WIDTH" || key == "HEIGHT" || key == "VIEWPOINT") continue;
    if (key == "FIELDS") {
      for (const std::string& w : words) fields.push_back({w});
    } else if (key == "SIZE") {
      std::vector<int> sizes;
      integers(sizes);
      for (std::size_t f = 0; f < fields.size(); ++f) {
        if (sizes[f] != 1 && sizes[f] != 2 && sizes[f] != 4 && sizes[f] != 8)
          throw Error(path, where, "field sizes must be 1, 2, 4 or 8");
        fields[f].size = sizes[f];
      }
    } else if (key == "TYPE") {
      if (words.size() != fields.size()) throw Error(path, where, "TYPE must have one entry per field");
      for (std::size_t f = 0; f < fields.size(); ++f) {
        if (words[f] != "I" && words[f] != "U" && words[f] != "F") throw Error(path, where, "types must be I, U or F");
        fields[f].type = words[f][0];
      }
    } else if (key == "COUNT") {
      std::vector<int> counts;
      integers(counts);
      for (std::size_t f = 0; f < fields.size(); ++f) fields[f].count = counts[f];
    } else if (key == "POINTS") {
      if (words.size() != 1 || std::from_chars(words[0].data(), words[0].data() + words[0].size(), points).ec != std::errc())
        throw Error(path, where, "POINTS must be one non-negative integer");
      has_points = true;
    } else if (key == "DATA") {
      data = words.empty() ? "?" : words[0];
    } else {
      throw Error(path, where, "unknown header keyword '" + key + "'");
    }
  }
  if (data == "binary_compressed")
    throw Error(path, "DATA", "binary_compressed PCD is not supported; re-save as binary or ascii");
  if (data != "ascii" && data != "binary") throw Error(path, "DATA", "unknown data encoding '" + data + "'");
  if (!has_points) throw Error(path, "header", "no POINTS line");
  int axis_field[3] = {-1, -1, -1};
  std::size_t record = 0, values_per_point = 0;
  for (std::size_t f = 0; f < fields.size(); ++f) {
    for (int a = 0; a < 3; ++a)
      if (fields[f].name == std::string(1, "xyz"[a]) && fields[f].count == 1) axis_field[a] = static_cast<int>(f);
    record += std::size_t(fields[f].size) * fields[f].count;
    values_per_point += fields[f].count;
  }
  for (int a = 0; a < 3; ++a)
    if (axis_field[a] < 0) throw Error(path, "FIELDS", std::string("no ") + "xyz"[a] + " field");
  const std::size_t body = bytes.size() - position;
  const std::size_t least = data == "binary" ? record : 2 * values_per_point;
  if (points > body / least)
    throw Error(path, fmt::format("point {}", body / least), fmt::format("file truncated: POINTS says {}", points));

  PointCloud cloud;
  cloud.resize(points);
  std::vector<AttributeColumn> columns(fields.size());
  std::vector<std::uint8_t> red, green, blue;
  for (std::size_t f = 0; f < fields.size(); ++f) {
    if (is_rgb(fields[f])) red.resize(points), green.resize(points), blue.resize(points);
    else columns[f] = column_for(fields[f], points);
  }
  auto keep_value = [&](std::size_t f, std::size_t i, double value, std::uint32_t packed) {
    const Field& field = fields[f];
    if (field.count != 1) return;
    if (static_cast<int>(f) == axis_field[0]) cloud.x[i] = float(value);
    else if (static_cast<int>(f) == axis_field[1]) cloud.y[i] = float(value);
    else if (static_cast<int>(f) == axis_field[2]) cloud.z[i] = float(value);
    else if (is_rgb(field)) red[i] = (packed >> 16) & 0xff, green[i] = (packed >> 8) & 0xff, blue[i] = packed & 0xff;
    else store(columns[f], i, value);
  };

  const char* at = bytes.data() + position;
  const char* end = bytes.data() + bytes.size();
  for (std::size_t i = 0; i < points; ++i) {
    for (std::size_t f = 0; f < fields.size(); ++f) {
      for (int c = 0; c < fields[f].count; ++c) {
        double value = 0;
        std::uint32_t packed = 0;
        if (data == "binary") {
          value = decode(fields[f], at);
          std::memcpy(&packed, at, std::min(4, fields[f].size));
          at += fields[f].size;
        } else {
          while (at < end && std::isspace(static_cast<unsigned char>(*at))) ++at;
          const char* token = at;
          while (at < end && !std::isspace(static_cast<unsigned char>(*at))) ++at;
          if (token == at) throw Error(path, fmt::format("point {}", i), fmt::format("file truncated: POINTS says {}", points));
          const auto result = std::from_chars(token, at, value);
          if (result.ec != std::errc() || result.ptr != at) {
            // PCL writes invalid points as "nan".
            if (std::string_view(token, at - token) == "nan") value = std::nan("");
            else throw Error(path, fmt::format("point {}", i), "not a number: '" + std::string(token, at) + "'");
          }
          if (is_rgb(fields[f])) {
            const float as_float = static_cast<float>(value);
            packed = fields[f].type == 'F' ? std::bit_cast<std::uint32_t>(as_float) : static_cast<std::uint32_t>(value);
          }
        }
        if (c == 0) keep_value(f, i, value, packed);
      }
    }
  }
  for (std::size_t f = 0; f < fields.size(); ++f)
    if (fields[f].count == 1 && static_cast<int>(f) != axis_field[0] && static_cast<int>(f) != axis_field[1] &&
        static_cast<int>(f) != axis_field[2] && !is_rgb(fields[f]))
      cloud.set(fields[f].name, std::move(columns[f]));
  if (!red.empty()) {
    cloud.set("red", std::move(red));
    cloud.set("green", std::move(green));
    cloud.set("blue", std::move(blue));
  }
  // Organised clouds mark missing returns with NaN coordinates: drop those points.
  std::vector<bool> valid(points);
  bool all_valid = true;
  for (std::size_t i = 0; i < points; ++i) {
    valid[i] = std::isfinite(cloud.x[i]) && std::isfinite(cloud.y[i]) && std::isfinite(cloud.z[i]);
    all_valid = all_valid && valid[i];
  }
  return all_valid ? cloud : cloud.select(valid);
}

}  // namespace glint::io
