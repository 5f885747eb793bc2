#include "io/pcd.h"

#include <fmt/format.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <limits>
#include <optional>
#include <set>
#include <string_view>
#include <vector>

#include "core/error.h"
#include "io/codec.h"
#include "io/file_bytes.h"

namespace glint::io {
namespace {

struct Field {
  std::string name;
  std::size_t size = 0;  // bytes per value
  char type = 0;         // 'I' signed integer, 'U' unsigned integer, 'F' floating point
  std::size_t count = 1;
};

struct PcdHeader {
  std::vector<Field> fields;
  std::optional<std::size_t> points, width, height;
  std::string data;  // ascii, binary or binary_compressed
  std::size_t body_offset = 0;
};

bool is_rgb(const Field& field) {
  return (field.name == "rgb" || field.name == "rgba") && field.size == 4 && field.count == 1;
}

// The column type for a field; there are no 64-bit integer columns, so those become double.
Scalar scalar_of(const Field& field) {
  if (field.type == 'F') return field.size == 8 ? Scalar::float64 : Scalar::float32;
  const bool is_signed = field.type == 'I';
  switch (field.size) {
    case 1:
      return is_signed ? Scalar::int8 : Scalar::uint8;
    case 2:
      return is_signed ? Scalar::int16 : Scalar::uint16;
    case 4:
      return is_signed ? Scalar::int32 : Scalar::uint32;
    default:
      return Scalar::float64;
  }
}

class HeaderParser {
 public:
  explicit HeaderParser(const std::string& path) : path_(path) {}

  // Takes one header line; false once it was the DATA line, which ends the header.
  bool take(const std::vector<std::string_view>& words, int line_number) {
    where_ = fmt::format("header line {}", line_number);
    if (words.empty() || words[0].starts_with('#')) return true;
    const std::string_view key = words[0];
    const std::vector<std::string_view> values(words.begin() + 1, words.end());
    if (key == "FIELDS") {
      header_.fields.clear();
      for (const std::string_view name : values) header_.fields.push_back({std::string(name)});
    } else if (key == "SIZE") {
      sizes(values);
    } else if (key == "TYPE") {
      types(values);
    } else if (key == "COUNT") {
      const std::vector<std::size_t> counts = per_field(key, values);
      for (std::size_t f = 0; f < counts.size(); ++f) header_.fields[f].count = counts[f];
    } else if (key == "WIDTH" || key == "HEIGHT" || key == "POINTS") {
      std::optional<std::size_t>& target = key == "WIDTH"    ? header_.width
                                           : key == "HEIGHT" ? header_.height
                                                             : header_.points;
      target = single_count(key, values);
    } else if (key == "DATA") {
      header_.data = values.empty() ? "" : std::string(values[0]);
      return false;
    } else if (key != "VERSION" && key != "VIEWPOINT") {
      fail(fmt::format("unknown header keyword '{}'", key));
    }
    return true;
  }

  PcdHeader finish(std::size_t body_offset) {
    header_.body_offset = body_offset;
    return std::move(header_);
  }

 private:
  [[noreturn]] void fail(const std::string& reason) const { throw Error(path_, where_, reason); }

  std::size_t single_count(std::string_view key, const std::vector<std::string_view>& values) {
    std::size_t count = 0;
    if (values.size() != 1 || !parse_count(values[0], count)) {
      fail(fmt::format("{} must be one non-negative integer", key));
    }
    return count;
  }

  // One positive integer per field; PCL's are ints, and the bound keeps record sizes from
  // overflowing.
  std::vector<std::size_t> per_field(std::string_view key,
                                     const std::vector<std::string_view>& values) {
    if (values.size() != header_.fields.size()) {
      fail(fmt::format("{} must have one entry per field ({})", key, header_.fields.size()));
    }
    constexpr std::size_t kLimit = std::numeric_limits<std::int32_t>::max();
    std::vector<std::size_t> numbers(values.size());
    for (std::size_t f = 0; f < values.size(); ++f) {
      if (!parse_count(values[f], numbers[f]) || numbers[f] == 0 || numbers[f] > kLimit) {
        fail(fmt::format("{}: '{}' is not a positive 32-bit integer", key, values[f]));
      }
    }
    return numbers;
  }

  void sizes(const std::vector<std::string_view>& values) {
    const std::vector<std::size_t> sizes = per_field("SIZE", values);
    for (std::size_t f = 0; f < sizes.size(); ++f) {
      if (!std::has_single_bit(sizes[f]) || sizes[f] > 8) fail("field sizes must be 1, 2, 4 or 8");
      header_.fields[f].size = sizes[f];
    }
  }

  void types(const std::vector<std::string_view>& values) {
    if (values.size() != header_.fields.size()) fail("TYPE must have one entry per field");
    for (std::size_t f = 0; f < values.size(); ++f) {
      if (values[f] != "I" && values[f] != "U" && values[f] != "F") fail("types must be I, U or F");
      header_.fields[f].type = values[f][0];
    }
  }

  const std::string& path_;
  std::string where_;
  PcdHeader header_;
};

PcdHeader parse_header(const std::string& path, const std::string& bytes) {
  HeaderParser parser(path);
  std::size_t position = 0;
  for (int line_number = 1;; ++line_number) {
    if (position >= bytes.size()) throw Error(path, "header", "no DATA line (not a PCD file?)");
    const std::size_t end = std::min(bytes.find('\n', position), bytes.size());
    const std::string_view line = std::string_view(bytes).substr(position, end - position);
    position = end + 1;
    if (!parser.take(split_words(line), line_number)) break;
  }
  return parser.finish(std::min(position, bytes.size()));
}

void check_header(const std::string& path, const PcdHeader& header) {
  if (header.data == "binary_compressed") {
    throw Error(path, "DATA", "binary_compressed PCD is not supported; re-save as binary or ascii");
  }
  if (header.data != "ascii" && header.data != "binary") {
    throw Error(path, "DATA", fmt::format("unknown data encoding '{}'", header.data));
  }
  for (const Field& field : header.fields) {
    if (field.size == 0 || field.type == 0) throw Error(path, "header", "no SIZE or no TYPE line");
    if (field.type == 'F' && field.size != 4 && field.size != 8) {
      throw Error(path, "header",
                  fmt::format("field '{}': F fields have 4 or 8 bytes", field.name));
    }
  }
  std::set<std::string_view> names;
  for (const Field& field : header.fields) {
    if (!names.insert(field.name).second && field.name != "_") {
      throw Error(path, "FIELDS", fmt::format("duplicate field '{}'", field.name));
    }
  }
  for (const char* axis : {"x", "y", "z"}) {
    const auto found = std::ranges::find(header.fields, axis, &Field::name);
    if (found == header.fields.end() || found->count != 1) {
      throw Error(path, "FIELDS", fmt::format("no {} field", axis));
    }
  }
}

// POINTS, or WIDTH × HEIGHT for files without it.
std::size_t point_count(const std::string& path, const PcdHeader& header) {
  if (header.points) return *header.points;
  if (!header.width || !header.height) throw Error(path, "header", "no POINTS line");
  if (*header.height != 0 &&
      *header.width > std::numeric_limits<std::size_t>::max() / *header.height) {
    throw Error(path, "header", "WIDTH × HEIGHT is too large");
  }
  return *header.width * *header.height;
}

// What happens to each field's values.
enum class Role { x, y, z, rgb, attribute, skip };

Role role_of(const Field& field) {
  if (field.name == "x") return Role::x;
  if (field.name == "y") return Role::y;
  if (field.name == "z") return Role::z;
  if (is_rgb(field)) return Role::rgb;
  // Multi-value fields (histograms, descriptors) and PCL's "_" padding are skipped.
  return field.count == 1 && field.name != "_" ? Role::attribute : Role::skip;
}

// A binary value; PCL writes them little-endian.
template <class T>
T load_little(const char* at) {
  T value;
  copy_value(at, reinterpret_cast<char*>(&value), sizeof value,
             std::endian::native == std::endian::big);
  return value;
}

// Reads the values of the point records, binary (little-endian, as PCL writes) or ascii.
class PcdBody {
 public:
  PcdBody(const std::string& path, std::string_view body, const PcdHeader& header,
          std::size_t points)
      : path_(path),
        at_(body.data()),
        end_(body.data() + body.size()),
        tokens_(at_, end_),
        binary_(header.data == "binary"),
        points_(points) {
    for (const Field& field : header.fields) {
      record_bytes_ += field.size * field.count;
      record_values_ += field.count;
    }
  }

  // The most points the rest of the data could hold (ascii: a character and a separator per value).
  std::size_t capacity() const {
    const std::size_t remaining = static_cast<std::size_t>(end_ - at_);
    return binary_ ? remaining / record_bytes_ : (remaining + 1) / (2 * record_values_);
  }

  double value(const Field& field, std::size_t point) {
    if (binary_) return binary_value(field, take(field.size, point));
    return number(next_token(point), point);
  }

  // The raw bits of a packed colour. In ascii, PCL writes them as an unsigned integer (newer
  // versions) or as the float with those bits (older ones).
  std::uint32_t packed(const Field& field, std::size_t point) {
    if (binary_) return load_little<std::uint32_t>(take(4, point));
    const std::string_view token = next_token(point);
    const double parsed = number(token, point);
    const bool integer_text =
        std::ranges::all_of(token, [](char c) { return c >= '0' && c <= '9'; });
    const Scalar type = field.type != 'F' || integer_text ? Scalar::uint32 : Scalar::float32;
    if (!fits(type, parsed)) fail(point, fmt::format("'{}' is not a packed colour", token));
    return type == Scalar::uint32 ? static_cast<std::uint32_t>(parsed)
                                  : std::bit_cast<std::uint32_t>(static_cast<float>(parsed));
  }

  void skip(const Field& field, std::size_t point) {
    if (binary_) {
      take(field.size * field.count, point);
      return;
    }
    for (std::size_t c = 0; c < field.count; ++c) next_token(point);
  }

  [[noreturn]] void truncated(std::size_t point) const {
    const std::string record = binary_ ? fmt::format(" of {} bytes", record_bytes_) : "";
    fail(point, fmt::format("file truncated: expected {} points{}", points_, record));
  }

  [[noreturn]] void fail(std::size_t point, const std::string& reason) const {
    throw Error(path_, fmt::format("point {}", point), reason);
  }

 private:
  static double binary_value(const Field& field, const char* at) {
    if (field.size == 8 && field.type == 'I') return double(load_little<std::int64_t>(at));
    if (field.size == 8 && field.type == 'U') return double(load_little<std::uint64_t>(at));
    return decode(scalar_of(field), at, std::endian::native == std::endian::big);
  }

  const char* take(std::size_t size, std::size_t point) {
    if (static_cast<std::size_t>(end_ - at_) < size) truncated(point);
    const char* start = at_;
    at_ += size;
    return start;
  }

  std::string_view next_token(std::size_t point) {
    const std::string_view token = tokens_.next();
    if (token.empty()) truncated(point);
    return token;
  }

  double number(std::string_view token, std::size_t point) const {
    double result = 0;
    if (!parse_number(token, result)) {
      fail(point, fmt::format("not a number: '{}'", token.substr(0, 32)));
    }
    return result;
  }

  const std::string& path_;
  const char* at_;
  const char* end_;
  Tokens tokens_;  // the ascii cursor; at_ is the binary one
  bool binary_;
  std::size_t points_;
  std::size_t record_bytes_ = 0;
  std::size_t record_values_ = 0;
};

// The columns being filled: positions in double (re-centred when the cloud is assembled),
// colours and other attributes beside them.
struct Columns {
  PointCloud cloud;
  std::vector<double> x, y, z;
  std::vector<std::uint8_t> red, green, blue;
  std::vector<std::optional<AttributeColumn>> attributes;  // per field, for Role::attribute
};

Columns make_columns(const std::vector<Field>& fields, const std::vector<Role>& roles,
                     std::size_t n) {
  Columns columns;
  columns.cloud.resize(n);
  columns.x.resize(n);
  columns.y.resize(n);
  columns.z.resize(n);
  columns.attributes.resize(fields.size());
  for (std::size_t f = 0; f < fields.size(); ++f) {
    if (roles[f] == Role::attribute) columns.attributes[f] = make_column(scalar_of(fields[f]), n);
    if (roles[f] == Role::rgb) {
      columns.red.resize(n);
      columns.green.resize(n);
      columns.blue.resize(n);
    }
  }
  return columns;
}

// NaN coordinates are kept (the point is dropped later); infinite ones are an error. Whether
// the others fit a float is decided after re-centring (set_positions).
double coordinate(PcdBody& body, double value, std::size_t point) {
  if (std::isinf(value)) body.fail(point, "non-finite coordinate");
  return value;
}

void read_point(PcdBody& body, const std::vector<Field>& fields, const std::vector<Role>& roles,
                Columns& columns, std::size_t i) {
  for (std::size_t f = 0; f < fields.size(); ++f) {
    const Field& field = fields[f];
    switch (roles[f]) {
      case Role::x:
        columns.x[i] = coordinate(body, body.value(field, i), i);
        break;
      case Role::y:
        columns.y[i] = coordinate(body, body.value(field, i), i);
        break;
      case Role::z:
        columns.z[i] = coordinate(body, body.value(field, i), i);
        break;
      case Role::rgb: {
        const std::uint32_t packed = body.packed(field, i);
        columns.red[i] = static_cast<std::uint8_t>(packed >> 16);
        columns.green[i] = static_cast<std::uint8_t>(packed >> 8);
        columns.blue[i] = static_cast<std::uint8_t>(packed);
        break;
      }
      case Role::attribute: {
        const double value = body.value(field, i);
        if (!fits(scalar_of(field), value)) {
          body.fail(i, fmt::format("{} does not fit field '{}'", value, field.name));
        }
        store(*columns.attributes[f], i, value);
        break;
      }
      case Role::skip:
        body.skip(field, i);
        break;
    }
  }
}

PointCloud assemble(Columns columns, const std::vector<Field>& fields, const std::string& path) {
  PointCloud& cloud = columns.cloud;
  for (std::size_t f = 0; f < fields.size(); ++f) {
    if (columns.attributes[f]) cloud.set(fields[f].name, std::move(*columns.attributes[f]));
  }
  if (std::ranges::any_of(fields, is_rgb)) {
    cloud.set("red", std::move(columns.red));
    cloud.set("green", std::move(columns.green));
    cloud.set("blue", std::move(columns.blue));
  }
  // Organised clouds mark missing returns with NaN coordinates: drop those points.
  std::vector<bool> valid(cloud.size());
  std::vector<double> x, y, z;
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    valid[i] = !std::isnan(columns.x[i]) && !std::isnan(columns.y[i]) && !std::isnan(columns.z[i]);
    if (!valid[i]) continue;
    x.push_back(columns.x[i]);
    y.push_back(columns.y[i]);
    z.push_back(columns.z[i]);
  }
  if (std::ranges::find(valid, false) != valid.end()) cloud = cloud.select(valid);
  set_positions(cloud, x.data(), y.data(), z.data(), x.size(), path);
  return std::move(cloud);
}

}  // namespace

PointCloud read_pcd(const std::string& path) {
  const std::string bytes = read_file_bytes(path);
  const PcdHeader header = parse_header(path, bytes);
  check_header(path, header);
  const std::size_t points = point_count(path, header);
  PcdBody body(path, std::string_view(bytes).substr(header.body_offset), header, points);
  std::vector<Role> roles;
  for (const Field& field : header.fields) roles.push_back(role_of(field));

  // Never allocate for more points than the rest of the file could hold.
  const std::size_t allocated = std::min(points, body.capacity());
  Columns columns = make_columns(header.fields, roles, allocated);
  for (std::size_t i = 0; i < points; ++i) {
    if (i == allocated) body.truncated(i);
    read_point(body, header.fields, roles, columns, i);
  }
  return assemble(std::move(columns), header.fields, path);
}

}  // namespace glint::io
