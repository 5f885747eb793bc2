#include "io/ply.h"

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <bit>
#include <cctype>
#include <charconv>
#include <cmath>
#include <cstring>
#include <fstream>
#include <limits>
#include <sstream>

#include "core/error.h"
#include "io/atomic_file.h"
#include "io/file_bytes.h"

namespace glint::io {
namespace {

enum class Type { int8, uint8, int16, uint16, int32, uint32, float32, float64 };

struct TypeInfo {
  const char* name;  // the name glint writes
  const char* alias;
  int size;
};
constexpr TypeInfo kTypes[] = {{"char", "int8", 1},    {"uchar", "uint8", 1},  {"short", "int16", 2},
                               {"ushort", "uint16", 2}, {"int", "int32", 4},    {"uint", "uint32", 4},
                               {"float", "float32", 4}, {"double", "float64", 8}};

int size_of(Type type) { return kTypes[static_cast<int>(type)].size; }

bool parse_type(const std::string& name, Type& type) {
  for (int t = 0; t < 8; ++t)
    if (name == kTypes[t].name || name == kTypes[t].alias) {
      type = static_cast<Type>(t);
      return true;
    }
  return false;
}

struct Property {
  std::string name;
  Type type = Type::float32;
  bool list = false;
  Type count_type = Type::uint8;
};

struct Element {
  std::string name;
  std::size_t count = 0;
  std::vector<Property> properties;
};

struct Header {
  PlyFormat format = PlyFormat::ascii;
  std::vector<Element> elements;
  std::size_t body_offset = 0;
};

std::vector<std::string> split_words(const std::string& line) {
  std::istringstream stream(line);
  std::vector<std::string> words;
  for (std::string word; stream >> word;) words.push_back(word);
  return words;
}

Header parse_header(const std::string& path, const std::string& bytes) {
  Header header;
  std::size_t position = 0;
  bool has_format = false;
  for (int line_number = 1;; ++line_number) {
    const std::size_t end = bytes.find('\n', position);
    if (end == std::string::npos) throw Error(path, "header", "no end_header line");
    std::string line = bytes.substr(position, end - position);
    position = end + 1;
    if (!line.empty() && line.back() == '\r') line.pop_back();
    const std::string where = fmt::format("header line {}", line_number);
    if (line_number == 1) {
      if (line != "ply") throw Error(path, "", "not a PLY file (the first line is not 'ply')");
      continue;
    }
    const std::vector<std::string> words = split_words(line);
    if (words.empty() || words[0] == "comment" || words[0] == "obj_info") continue;
    if (words[0] == "end_header") break;
    if (words[0] == "format") {
      if (words.size() != 3) throw Error(path, where, "expected 'format <encoding> 1.0'");
      if (words[1] == "ascii") header.format = PlyFormat::ascii;
      else if (words[1] == "binary_little_endian") header.format = PlyFormat::binary_little_endian;
      else if (words[1] == "binary_big_endian") header.format = PlyFormat::binary_big_endian;
      else throw Error(path, where, "unknown format '" + words[1] + "'");
      has_format = true;
    } else if (words[0] == "element") {
      std::size_t count = 0;
      if (words.size() != 3 ||
          std::from_chars(words[2].data(), words[2].data() + words[2].size(), count).ec != std::errc())
        throw Error(path, where, "expected 'element <name> <count>'");
      header.elements.push_back({words[1], count, {}});
    } else if (words[0] == "property") {
      if (header.elements.empty()) throw Error(path, where, "property before any element");
      Property property;
      if (words.size() == 5 && words[1] == "list") {
        property.list = true;
        if (!parse_type(words[2], property.count_type) || !parse_type(words[3], property.type))
          throw Error(path, where, "unknown list property types '" + words[2] + " " + words[3] + "'");
        property.name = words[4];
      } else if (words.size() == 3) {
        if (!parse_type(words[1], property.type))
          throw Error(path, where, "unknown property type '" + words[1] + "'");
        property.name = words[2];
      } else {
        throw Error(path, where, "expected 'property <type> <name>' or 'property list ...'");
      }
      header.elements.back().properties.push_back(property);
    } else {
      throw Error(path, where, "unknown header keyword '" + words[0] + "'");
    }
  }
  if (!has_format) throw Error(path, "header", "no format line");
  header.body_offset = position;
  return header;
}

// Whether an ascii value can be stored in `type` (integers: whole and in range).
bool fits(Type type, double value) {
  auto in = [value](auto low, auto high) {
    return value == std::floor(value) && value >= double(low) && value <= double(high);
  };
  switch (type) {
    case Type::int8: return in(INT8_MIN, INT8_MAX);
    case Type::uint8: return in(0, UINT8_MAX);
    case Type::int16: return in(INT16_MIN, INT16_MAX);
    case Type::uint16: return in(0, UINT16_MAX);
    case Type::int32: return in(INT32_MIN, INT32_MAX);
    case Type::uint32: return in(0, UINT32_MAX);
    // Finite doubles below FLT_MAX + half an ulp round to a finite float.
    case Type::float32: return !std::isfinite(value) || std::fabs(value) < std::ldexp(1.0, 128) - std::ldexp(1.0, 103);
    case Type::float64: return true;
  }
  return false;
}

// ---- binary decoding

template <class T>
T load(const char* at, bool swap) {
  std::array<char, sizeof(T)> raw;
  std::memcpy(raw.data(), at, sizeof(T));
  if (swap) std::reverse(raw.begin(), raw.end());
  return std::bit_cast<T>(raw);
}

double load_as_double(Type type, const char* at, bool swap) {
  switch (type) {
    case Type::int8: return load<std::int8_t>(at, swap);
    case Type::uint8: return load<std::uint8_t>(at, swap);
    case Type::int16: return load<std::int16_t>(at, swap);
    case Type::uint16: return load<std::uint16_t>(at, swap);
    case Type::int32: return load<std::int32_t>(at, swap);
    case Type::uint32: return load<std::uint32_t>(at, swap);
    case Type::float32: return load<float>(at, swap);
    case Type::float64: return load<double>(at, swap);
  }
  return 0.0;
}

AttributeColumn make_column(Type type, std::size_t n) {
  switch (type) {
    case Type::int8: return std::vector<std::int8_t>(n);
    case Type::uint8: return std::vector<std::uint8_t>(n);
    case Type::int16: return std::vector<std::int16_t>(n);
    case Type::uint16: return std::vector<std::uint16_t>(n);
    case Type::int32: return std::vector<std::int32_t>(n);
    case Type::uint32: return std::vector<std::uint32_t>(n);
    case Type::float32: return std::vector<float>(n);
    case Type::float64: return std::vector<double>(n);
  }
  return {};
}

// Where a vertex property's values go: a position axis, an attribute column, or nowhere (lists).
struct Sink {
  int axis = -1;                       // 0, 1, 2 for x, y, z
  AttributeColumn* column = nullptr;
  unsigned char* raw = nullptr;        // the column's bytes (native endianness)
};

class BodyReader {
 public:
  BodyReader(const std::string& path, const std::string& bytes, std::size_t offset, PlyFormat format)
      : path_(path), at_(bytes.data() + offset), end_(bytes.data() + bytes.size()),
        swap_((format == PlyFormat::binary_big_endian) == (std::endian::native == std::endian::little)),
        ascii_(format == PlyFormat::ascii) {}

  std::size_t remaining() const { return static_cast<std::size_t>(end_ - at_); }

  // One value of `type`, as double (ascii or binary).
  double value(Type type, const Element& element, std::size_t index) {
    if (ascii_) return ascii_value(type, element, index);
    const int size = size_of(type);
    if (remaining() < std::size_t(size)) truncated(element, index);
    const double result = load_as_double(type, at_, swap_);
    at_ += size;
    return result;
  }

  // Binary only: copies one value's bytes, byte-swapped to native order, to `out`.
  void raw(Type type, unsigned char* out, const Element& element, std::size_t index) {
    const int size = size_of(type);
    if (remaining() < std::size_t(size)) truncated(element, index);
    std::memcpy(out, at_, size);
    if (swap_) std::reverse(out, out + size);
    at_ += size;
  }

  bool ascii() const { return ascii_; }

  void skip_list(const Property& property, const Element& element, std::size_t index) {
    const double count = value(property.count_type, element, index);
    if (!(count >= 0) || count != std::floor(count))
      throw Error(path_, element_where(element, index), "invalid list length");
    if (!ascii_) {
      const std::size_t bytes = static_cast<std::size_t>(count) * size_of(property.type);
      if (remaining() < bytes) truncated(element, index);
      at_ += bytes;
      return;
    }
    for (std::size_t i = 0; i < static_cast<std::size_t>(count); ++i) value(property.type, element, index);
  }

  void skip_element(const Element& element) {
    bool fixed = !ascii_;
    std::size_t record = 0;
    for (const Property& p : element.properties) {
      fixed = fixed && !p.list;
      record += size_of(p.type);
    }
    if (fixed) {
      if (element.count > remaining() / std::max<std::size_t>(record, 1)) truncated(element, remaining() / std::max<std::size_t>(record, 1));
      at_ += element.count * record;
      return;
    }
    for (std::size_t i = 0; i < element.count; ++i)
      for (const Property& p : element.properties) p.list ? skip_list(p, element, i) : void(value(p.type, element, i));
  }

  [[noreturn]] void truncated(const Element& element, std::size_t index) const {
    throw Error(path_, element_where(element, index),
                fmt::format("file truncated: the header announces {} {} elements", element.count, element.name));
  }

 private:
  static std::string element_where(const Element& element, std::size_t index) {
    return fmt::format("{} {}", element.name, index);
  }

  double ascii_value(Type type, const Element& element, std::size_t index) {
    while (at_ < end_ && std::isspace(static_cast<unsigned char>(*at_))) ++at_;
    if (at_ == end_) truncated(element, index);
    const char* token_end = at_;
    while (token_end < end_ && !std::isspace(static_cast<unsigned char>(*token_end))) ++token_end;
    double result = 0.0;
    const auto [stop, ec] = std::from_chars(at_, token_end, result);
    if (ec != std::errc() || stop != token_end)
      throw Error(path_, element_where(element, index),
                  "not a number: '" + std::string(at_, std::min<std::size_t>(token_end - at_, 32)) + "'");
    if (!fits(type, result))
      throw Error(path_, element_where(element, index),
                  fmt::format("{} does not fit the property type {}", std::string(at_, token_end),
                              kTypes[static_cast<int>(type)].name));
    at_ = token_end;
    return result;
  }

  const std::string& path_;
  const char* at_;
  const char* end_;
  bool swap_;
  bool ascii_;
};

template <class T>
void store(AttributeColumn& column, std::size_t i, double value) {
  std::get<std::vector<T>>(column)[i] = static_cast<T>(value);
}

void store_value(AttributeColumn& column, Type type, std::size_t i, double value) {
  switch (type) {
    case Type::int8: return store<std::int8_t>(column, i, value);
    case Type::uint8: return store<std::uint8_t>(column, i, value);
    case Type::int16: return store<std::int16_t>(column, i, value);
    case Type::uint16: return store<std::uint16_t>(column, i, value);
    case Type::int32: return store<std::int32_t>(column, i, value);
    case Type::uint32: return store<std::uint32_t>(column, i, value);
    case Type::float32: return store<float>(column, i, value);
    case Type::float64: return store<double>(column, i, value);
  }
}

unsigned char* column_bytes(AttributeColumn& column) {
  return std::visit([](auto& values) { return reinterpret_cast<unsigned char*>(values.data()); }, column);
}

PointCloud read_vertices(const std::string& path, BodyReader& body, const Element& vertex) {
  // A record needs at least one byte (binary) or two characters (ascii) per property: a count
  // beyond that cannot be satisfied, so fail before allocating for it.
  const std::size_t least = body.ascii() ? 2 : 1;
  if (vertex.count > body.remaining() / (least * std::max<std::size_t>(vertex.properties.size(), 1)))
    body.truncated(vertex, body.remaining() / (least * std::max<std::size_t>(vertex.properties.size(), 1)));

  PointCloud cloud;
  cloud.resize(vertex.count);
  std::vector<NamedAttribute> attributes;
  attributes.reserve(vertex.properties.size());
  std::vector<Sink> sinks(vertex.properties.size());
  std::vector<Type> position_types(3, Type::float32);
  bool has_axis[3] = {false, false, false};
  for (std::size_t p = 0; p < vertex.properties.size(); ++p) {
    const Property& property = vertex.properties[p];
    if (property.list) continue;
    const int axis = property.name == "x" ? 0 : property.name == "y" ? 1 : property.name == "z" ? 2 : -1;
    if (axis >= 0 && !has_axis[axis]) {
      sinks[p].axis = axis;
      has_axis[axis] = true;
      continue;
    }
    attributes.push_back({property.name, make_column(property.type, vertex.count)});
  }
  for (int a = 0; a < 3; ++a)
    if (!has_axis[a]) throw Error(path, "header", std::string("the vertex element has no ") + "xyz"[a] + " property");
  for (std::size_t p = 0, a = 0; p < vertex.properties.size(); ++p) {
    if (vertex.properties[p].list || sinks[p].axis >= 0) continue;
    sinks[p].column = &attributes[a++].values;
    sinks[p].raw = column_bytes(*sinks[p].column);
  }

  float* axes[3] = {cloud.x.data(), cloud.y.data(), cloud.z.data()};
  for (std::size_t i = 0; i < vertex.count; ++i) {
    for (std::size_t p = 0; p < vertex.properties.size(); ++p) {
      const Property& property = vertex.properties[p];
      const Sink& sink = sinks[p];
      if (property.list) {
        body.skip_list(property, vertex, i);
      } else if (sink.axis >= 0) {
        const double value = body.value(property.type, vertex, i);
        if (!std::isfinite(value)) throw Error(path, fmt::format("vertex {}", i), "non-finite coordinate");
        axes[sink.axis][i] = static_cast<float>(value);
      } else if (body.ascii()) {
        store_value(*sink.column, property.type, i, body.value(property.type, vertex, i));
      } else {
        body.raw(property.type, sink.raw + i * size_of(property.type), vertex, i);
      }
    }
  }
  for (NamedAttribute& attribute : attributes) cloud.set(attribute.name, std::move(attribute.values));
  return cloud;
}

// ---- writing

Type type_of(const AttributeColumn& column) { return static_cast<Type>(column.index()); }

void write_ascii_value(std::string& out, double value, Type type) {
  char buffer[64];
  std::to_chars_result result{};
  if (type == Type::float32) result = std::to_chars(buffer, buffer + sizeof buffer, static_cast<float>(value));
  else if (type == Type::float64) result = std::to_chars(buffer, buffer + sizeof buffer, value);
  else result = std::to_chars(buffer, buffer + sizeof buffer, static_cast<long long>(value));
  out.append(buffer, result.ptr);
}

template <class T>
void put(std::string& out, T value, bool swap) {
  auto raw = std::bit_cast<std::array<char, sizeof(T)>>(value);
  if (swap) std::reverse(raw.begin(), raw.end());
  out.append(raw.data(), raw.size());
}

}  // namespace

PointCloud read_ply(const std::string& path) {
  const std::string bytes = read_file_bytes(path);
  const Header header = parse_header(path, bytes);
  BodyReader body(path, bytes, header.body_offset, header.format);
  for (const Element& element : header.elements) {
    if (element.name == "vertex") return read_vertices(path, body, element);
    body.skip_element(element);
  }
  throw Error(path, "header", "no vertex element");
}

void write_ply(const std::string& path, const PointCloud& cloud, PlyFormat format) {
  static const char* format_names[] = {"ascii", "binary_little_endian", "binary_big_endian"};
  std::string out = fmt::format("ply\nformat {} 1.0\ncomment generated by glint\nelement vertex {}\n"
                                "property float x\nproperty float y\nproperty float z\n",
                                format_names[static_cast<int>(format)], cloud.size());
  for (const NamedAttribute& attribute : cloud.attributes())
    out += fmt::format("property {} {}\n", kTypes[static_cast<int>(type_of(attribute.values))].name,
                       attribute.name);
  out += "end_header\n";

  const bool ascii = format == PlyFormat::ascii;
  const bool swap = (format == PlyFormat::binary_big_endian) == (std::endian::native == std::endian::little);
  std::size_t record = 12;
  for (const NamedAttribute& attribute : cloud.attributes()) record += size_of(type_of(attribute.values));
  out.reserve(out.size() + cloud.size() * (ascii ? 3 * record : record));
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    if (ascii) {
      for (const float value : {cloud.x[i], cloud.y[i], cloud.z[i]}) {
        write_ascii_value(out, value, Type::float32);
        out += ' ';
      }
      for (const NamedAttribute& attribute : cloud.attributes()) {
        write_ascii_value(out, column_value(attribute.values, i), type_of(attribute.values));
        out += ' ';
      }
      out.back() = '\n';
      continue;
    }
    put(out, cloud.x[i], swap);
    put(out, cloud.y[i], swap);
    put(out, cloud.z[i], swap);
    for (const NamedAttribute& attribute : cloud.attributes())
      std::visit([&](const auto& values) { put(out, values[i], swap); }, attribute.values);
  }
  AtomicFile file(path);
  file.stream().write(out.data(), static_cast<std::streamsize>(out.size()));
  file.commit();
}

}  // namespace glint::io
