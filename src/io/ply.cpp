#include "io/ply.h"

#include <fmt/format.h>

#include <algorithm>
#include <bit>
#include <cctype>
#include <cmath>
#include <new>
#include <optional>
#include <string_view>
#include <vector>

#include "core/error.h"
#include "core/limits.h"
#include "io/atomic_file.h"
#include "io/codec.h"
#include "io/file_bytes.h"

namespace glint::io {
namespace {

// PLY type names, indexed by Scalar: the classic names (which glint writes) and their aliases.
constexpr std::string_view kTypeNames[] = {"char", "uchar", "short", "ushort",
                                           "int",  "uint",  "float", "double"};
constexpr std::string_view kTypeAliases[] = {"int8",  "uint8",  "int16",   "uint16",
                                             "int32", "uint32", "float32", "float64"};
constexpr std::string_view kFormatNames[] = {"ascii", "binary_little_endian", "binary_big_endian"};

// Whether binary values of `format` are in the opposite byte order to this machine's.
bool needs_swap(PlyFormat format) {
  return (format == PlyFormat::binary_big_endian) != (std::endian::native == std::endian::big);
}

std::string_view type_name(Scalar type) { return kTypeNames[static_cast<int>(type)]; }

std::optional<Scalar> parse_type(std::string_view name) {
  for (int t = 0; t < 8; ++t) {
    if (name == kTypeNames[t] || name == kTypeAliases[t]) return static_cast<Scalar>(t);
  }
  return std::nullopt;
}

// ---- header

struct Property {
  std::string name;
  Scalar type = Scalar::float32;      // for lists: the type of the items
  std::optional<Scalar> list_length;  // for lists: the type of the length prefix
};

struct Element {
  std::string name;
  std::size_t count = 0;
  std::vector<Property> properties;

  bool has_lists() const {
    return std::ranges::any_of(properties,
                               [](const Property& p) { return p.list_length.has_value(); });
  }
  // Bytes of one binary record, counting every list as empty.
  std::size_t least_bytes() const {
    std::size_t bytes = 0;
    for (const Property& p : properties) bytes += size_of(p.list_length.value_or(p.type));
    return bytes;
  }
  const Property* find(std::string_view property) const {
    for (const Property& p : properties) {
      if (p.name == property) return &p;
    }
    return nullptr;
  }
};

struct Header {
  PlyFormat format = PlyFormat::ascii;
  std::vector<Element> elements;
  std::size_t body_offset = 0;
};

// The line starting at `position` without its line ending; moves `position` past it.
std::optional<std::string_view> next_line(const std::string& bytes, std::size_t& position) {
  if (position >= bytes.size()) return std::nullopt;
  std::size_t end = bytes.find('\n', position);
  if (end == std::string::npos) end = bytes.size();
  std::string_view line(bytes.data() + position, end - position);
  position = end + 1;
  if (line.ends_with('\r')) line.remove_suffix(1);
  return line;
}

class HeaderParser {
 public:
  explicit HeaderParser(const std::string& path) : path_(path) {}

  // Takes one header line (already split into words); false once it was "end_header".
  bool take(const std::vector<std::string_view>& words, int line_number) {
    where_ = fmt::format("header line {}", line_number);
    if (words.empty() || words[0] == "comment" || words[0] == "obj_info") return true;
    if (words[0] == "end_header") return false;
    if (words[0] == "format") {
      format(words);
    } else if (words[0] == "element") {
      element(words);
    } else if (words[0] == "property") {
      property(words);
    } else {
      fail(fmt::format("unknown header keyword '{}'", words[0]));
    }
    return true;
  }

  Header finish() {
    if (!has_format_) throw Error(path_, "header", "no format line");
    return std::move(header_);
  }

 private:
  [[noreturn]] void fail(const std::string& reason) const { throw Error(path_, where_, reason); }

  void format(const std::vector<std::string_view>& words) {
    if (words.size() != 3) fail("expected 'format <encoding> <version>'");
    const auto* found = std::ranges::find(kFormatNames, words[1]);
    if (found == std::end(kFormatNames)) fail(fmt::format("unknown format '{}'", words[1]));
    header_.format = static_cast<PlyFormat>(found - std::begin(kFormatNames));
    has_format_ = true;
  }

  void element(const std::vector<std::string_view>& words) {
    Element element;
    if (words.size() != 3 || !parse_count(words[2], element.count)) {
      fail("expected 'element <name> <count>'");
    }
    element.name = words[1];
    header_.elements.push_back(std::move(element));
  }

  void property(const std::vector<std::string_view>& words) {
    if (header_.elements.empty()) fail("property before any element");
    Property property;
    if (words.size() == 5 && words[1] == "list") {
      property.list_length = parse_type(words[2]);
      if (!property.list_length) fail(fmt::format("unknown list length type '{}'", words[2]));
      property.type = known_type(words[3]);
    } else if (words.size() == 3) {
      property.type = known_type(words[1]);
    } else {
      fail("expected 'property <type> <name>' or 'property list <type> <type> <name>'");
    }
    property.name = words.back();
    header_.elements.back().properties.push_back(std::move(property));
  }

  Scalar known_type(std::string_view name) const {
    const std::optional<Scalar> type = parse_type(name);
    if (!type) fail(fmt::format("unknown property type '{}'", name));
    return *type;
  }

  const std::string& path_;
  std::string where_;
  Header header_;
  bool has_format_ = false;
};

Header parse_header(const std::string& path, const std::string& bytes) {
  std::size_t position = 0;
  if (next_line(bytes, position) != "ply") {
    throw Error(path, "", "not a PLY file (the first line is not 'ply')");
  }
  HeaderParser parser(path);
  for (int line_number = 2;; ++line_number) {
    const std::optional<std::string_view> line = next_line(bytes, position);
    if (!line) throw Error(path, "header", "no end_header line");
    if (!parser.take(split_words(*line), line_number)) break;
  }
  Header header = parser.finish();
  header.body_offset = std::min(position, bytes.size());
  return header;
}

// ---- body

// Where one vertex property goes: a position axis, an attribute column, or nowhere (lists).
struct Slot {
  const Property* property = nullptr;
  double* axis = nullptr;  // positions are read in double and re-centred (set_positions)
  AttributeColumn* column = nullptr;
  char* column_bytes = nullptr;
};

std::string plural(const Element& element) {
  return element.name == "vertex" ? "vertices" : fmt::format("'{}' elements", element.name);
}

std::string record_name(const Element& element, std::size_t index) {
  return fmt::format("{} {}", element.name, index);
}

// Elements with nothing to read need no walking (their count may be anything).
bool is_empty_record(const Element& element) { return element.properties.empty(); }

bool is_list_length(double length) { return length >= 0 && length == std::floor(length); }

class BinaryBody {
 public:
  BinaryBody(const std::string& path, std::string_view body, bool swap)
      : path_(path), at_(body.data()), end_(body.data() + body.size()), swap_(swap) {}

  std::size_t capacity(const Element& element) const {
    return is_empty_record(element) ? element.count : remaining() / element.least_bytes();
  }

  double value(Scalar type, const Element& element, std::size_t index) {
    return decode(type, take(size_of(type), element, index), swap_);
  }

  void attribute(const Slot& slot, const Element& element, std::size_t index) {
    const std::size_t size = size_of(slot.property->type);
    copy_value(take(size, element, index), slot.column_bytes + index * size, size, swap_);
  }

  // Reads the length prefix of a list property.
  std::size_t list_length(const Property& property, const Element& element, std::size_t index) {
    const double length = value(*property.list_length, element, index);
    if (!is_list_length(length)) {
      throw Error(path_, record_name(element, index), "invalid list length");
    }
    if (length > double(remaining())) truncated(element, index);
    return static_cast<std::size_t>(length);
  }

  void skip_list(const Property& property, const Element& element, std::size_t index) {
    take(list_length(property, element, index) * size_of(property.type), element, index);
  }

  bool skip_fixed(const Element& element) {
    if (element.has_lists() || is_empty_record(element)) return is_empty_record(element);
    const std::size_t records = capacity(element);
    if (element.count > records) truncated(element, records);
    at_ += element.count * element.least_bytes();
    return true;
  }

  [[noreturn]] void truncated(const Element& element, std::size_t index) const {
    const std::string record =
        element.has_lists() ? "" : fmt::format(" of {} bytes", element.least_bytes());
    throw Error(
        path_, record_name(element, index),
        fmt::format("file truncated: expected {} {}{}", element.count, plural(element), record));
  }

 private:
  std::size_t remaining() const { return static_cast<std::size_t>(end_ - at_); }

  const char* take(std::size_t size, const Element& element, std::size_t index) {
    if (remaining() < size) truncated(element, index);
    const char* start = at_;
    at_ += size;
    return start;
  }

  const std::string& path_;
  const char* at_;
  const char* end_;
  bool swap_;
};

// An ascii body: one record per line (blank lines are skipped). A line with fewer or more values
// than its element's properties is an error naming the line, never read on into the next one.
class AsciiBody {
 public:
  // `first_line`: the file's line number of the body's first line.
  AsciiBody(const std::string& path, std::string_view body, std::size_t first_line)
      : path_(path), rest_(body), line_number_(first_line - 1) {}

  // A record needs a token per property, and tokens are at least one character and a separator.
  std::size_t capacity(const Element& element) const {
    if (is_empty_record(element)) return element.count;
    return (rest_.size() + 1) / (2 * element.properties.size());
  }

  double value(Scalar type, const Element& element, std::size_t index) {
    const std::string_view token = record(element, index).next();
    if (token.empty()) {
      if (rest_.find_first_not_of(" \t\r\n") == std::string_view::npos) truncated(element, index);
      fail(element, index,
           fmt::format("the line ends early: it has fewer values than the {} properties of {}",
                       element.properties.size(), plural(element)));
    }
    double result = 0;
    if (!parse_number(token, result)) {
      fail(element, index, fmt::format("not a number: '{}'", token.substr(0, 32)));
    }
    if (!fits(type, result)) {
      fail(element, index,
           fmt::format("{} does not fit the property type {}", token, type_name(type)));
    }
    return result;
  }

  void attribute(const Slot& slot, const Element& element, std::size_t index) {
    store(*slot.column, index, value(slot.property->type, element, index));
  }

  // Reads the length prefix of a list property.
  std::size_t list_length(const Property& property, const Element& element, std::size_t index) {
    const double length = value(*property.list_length, element, index);
    if (!is_list_length(length)) fail(element, index, "invalid list length");
    // Each item needs a token of at least one character.
    if (length > double(line_.remaining()))
      fail(element, index, "the list is longer than its line");
    return static_cast<std::size_t>(length);
  }

  void skip_list(const Property& property, const Element& element, std::size_t index) {
    const std::size_t length = list_length(property, element, index);
    for (std::size_t item = 0; item < length; ++item) value(property.type, element, index);
  }

  bool skip_fixed(const Element& element) { return is_empty_record(element); }

  [[noreturn]] void truncated(const Element& element, std::size_t index) const {
    throw Error(path_, record_name(element, index),
                fmt::format("file truncated: expected {} {}", element.count, plural(element)));
  }

  // Checks that the last record read left nothing on its line.
  void finish() {
    if (!record_element_) return;
    const std::string_view extra = line_.next();
    if (!extra.empty())
      fail(*record_element_, record_index_,
           fmt::format("the line has more values than the {} properties of {} (from '{}')",
                       record_element_->properties.size(), plural(*record_element_),
                       extra.substr(0, 32)));
  }

 private:
  // The tokens of record `index` of `element`: a new record starts on the next non-blank line.
  Tokens& record(const Element& element, std::size_t index) {
    if (&element == record_element_ && index == record_index_) return line_;
    finish();
    record_element_ = &element;
    record_index_ = index;
    std::string_view line;
    do {
      if (rest_.empty()) truncated(element, index);
      const std::size_t end = rest_.find('\n');
      line = rest_.substr(0, end);
      rest_ = end == std::string_view::npos ? std::string_view() : rest_.substr(end + 1);
      ++line_number_;
    } while (line.find_first_not_of(" \t\r") == std::string_view::npos);
    line_ = Tokens(line.data(), line.data() + line.size());
    return line_;
  }

  [[noreturn]] void fail(const Element& element, std::size_t index,
                         const std::string& reason) const {
    throw Error(path_, fmt::format("line {} ({})", line_number_, record_name(element, index)),
                reason);
  }

  const std::string& path_;
  std::string_view rest_;  // the body after the current record's line
  Tokens line_{nullptr, nullptr};
  std::size_t line_number_;
  const Element* record_element_ = nullptr;
  std::size_t record_index_ = 0;
};

template <class Body>
void skip_element(Body& body, const Element& element) {
  if (body.skip_fixed(element)) return;
  for (std::size_t i = 0; i < element.count; ++i) {
    for (const Property& property : element.properties) {
      if (property.list_length) {
        body.skip_list(property, element, i);
      } else {
        body.value(property.type, element, i);
      }
    }
  }
}

// Positions in double, before set_positions() re-centres them into the cloud's floats.
struct Positions {
  std::vector<double> x, y, z;
  double* axis(const std::string& name) {
    if (name == "x") return x.data();
    if (name == "y") return y.data();
    if (name == "z") return z.data();
    return nullptr;
  }
};

// One slot per vertex property; `attributes` receives a column for each non-position scalar.
std::vector<Slot> plan_slots(const Element& vertex, std::size_t count, Positions& positions,
                             std::vector<NamedAttribute>& attributes) {
  attributes.reserve(vertex.properties.size());  // the slots point into it
  std::vector<Slot> slots;
  for (const Property& property : vertex.properties) {
    Slot slot{&property};
    if (!property.list_length) slot.axis = positions.axis(property.name);
    if (!property.list_length && !slot.axis) {
      attributes.push_back({property.name, make_column(property.type, count)});
      slot.column = &attributes.back().values;
      slot.column_bytes = column_bytes(*slot.column);
    }
    slots.push_back(slot);
  }
  return slots;
}

template <class Body>
PointCloud read_vertices(const std::string& path, Body& body, const Element& vertex) {
  // Never allocate for more vertices than the rest of the file could hold.
  const std::size_t allocated = std::min(vertex.count, body.capacity(vertex));
  Positions positions;
  try {
    for (std::vector<double>* axis : {&positions.x, &positions.y, &positions.z})
      axis->resize(allocated);
  } catch (const std::bad_alloc&) {
    limits::throw_out_of_memory(fmt::format("the positions of {} vertices", allocated),
                                24.0 * allocated);
  }
  std::vector<NamedAttribute> attributes;
  const std::vector<Slot> slots = plan_slots(vertex, allocated, positions, attributes);
  for (std::size_t i = 0; i < vertex.count; ++i) {
    if (i == allocated) body.truncated(vertex, i);
    for (const Slot& slot : slots) {
      if (slot.axis) {
        slot.axis[i] = body.value(slot.property->type, vertex, i);
      } else if (slot.column) {
        body.attribute(slot, vertex, i);
      } else {
        body.skip_list(*slot.property, vertex, i);
      }
    }
  }
  PointCloud cloud;
  set_positions(cloud, positions.x.data(), positions.y.data(), positions.z.data(), allocated, path);
  for (NamedAttribute& attribute : attributes) {
    cloud.set(attribute.name, std::move(attribute.values));
  }
  return cloud;
}

template <class Body>
PointCloud read_body(const std::string& path, Body& body, const Header& header,
                     const Element& vertex) {
  for (const Element& element : header.elements) {
    if (&element == &vertex) break;
    skip_element(body, element);
  }
  return read_vertices(path, body, vertex);
}

// The face element's index list: "vertex_indices", or "vertex_index" as some writers name it.
const Property& face_list(const std::string& path, const Element& face) {
  for (const char* name : {"vertex_indices", "vertex_index"}) {
    const Property* property = face.find(name);
    if (property && property->list_length) return *property;
  }
  throw Error(path, "face", "needs a vertex_indices list");
}

// Appends the faces' polygons, fan-triangulated, to `triangles`.
template <class Body>
void read_faces(const std::string& path, Body& body, const Element& face, std::size_t vertex_count,
                std::vector<Eigen::Vector3i>& triangles) {
  const Property& list = face_list(path, face);
  std::vector<int> polygon;
  for (std::size_t i = 0; i < face.count; ++i) {
    for (const Property& property : face.properties) {
      if (&property != &list) {
        if (property.list_length) {
          body.skip_list(property, face, i);
        } else {
          body.value(property.type, face, i);
        }
        continue;
      }
      polygon.resize(body.list_length(property, face, i));
      for (int& corner : polygon) {
        const double index = body.value(property.type, face, i);
        if (!(index >= 0 && index < double(vertex_count))) {
          throw Error(path, record_name(face, i), "vertex index out of range");
        }
        corner = static_cast<int>(index);
      }
      for (std::size_t c = 2; c < polygon.size(); ++c) {
        triangles.emplace_back(polygon[0], polygon[c - 1], polygon[c]);
      }
    }
  }
}

template <class Body>
PlyMesh read_mesh_body(const std::string& path, Body& body, const Header& header,
                       const Element& vertex) {
  PlyMesh mesh;
  for (const Element& element : header.elements) {
    if (&element == &vertex) {
      mesh.vertices = read_vertices(path, body, vertex);
    } else if (element.name == "face") {
      read_faces(path, body, element, vertex.count, mesh.triangles);
    } else {
      skip_element(body, element);
    }
  }
  if (mesh.triangles.empty()) throw Error(path, "face", "the mesh has no faces");
  return mesh;
}

// The first name that occurs twice, if any.
std::optional<std::string> duplicate_name(const std::vector<Property>& properties) {
  std::vector<std::string_view> names;
  for (const Property& property : properties) names.push_back(property.name);
  std::ranges::sort(names);
  const auto twice = std::ranges::adjacent_find(names);
  return twice == names.end() ? std::nullopt : std::optional<std::string>(*twice);
}

// The vertex element, with x, y and z; throws glint::Error when there is none.
const Element& vertex_element(const std::string& path, const Header& header) {
  const auto vertex = std::ranges::find(header.elements, "vertex", &Element::name);
  if (vertex == header.elements.end()) throw Error(path, "header", "no vertex element");
  if (const auto name = duplicate_name(vertex->properties)) {
    throw Error(path, "header", fmt::format("duplicate vertex property '{}'", *name));
  }
  for (const char* axis : {"x", "y", "z"}) {
    const Property* property = vertex->find(axis);
    if (!property || property->list_length) {
      throw Error(path, "header", fmt::format("the vertex element has no {} property", axis));
    }
  }
  return *vertex;
}

// Parses the header and calls read(body, header, vertex element) with the reader of the file's
// encoding.
template <class Read>
auto read_with_body(const std::string& path, const Read& read) {
  const std::string bytes = read_file_bytes(path);
  const Header header = parse_header(path, bytes);
  const Element& vertex = vertex_element(path, header);
  const std::string_view body = std::string_view(bytes).substr(header.body_offset);
  if (header.format == PlyFormat::ascii) {
    const auto header_lines = std::count(bytes.begin(), bytes.begin() + header.body_offset, '\n');
    AsciiBody ascii(path, body, static_cast<std::size_t>(header_lines) + 1);
    auto result = read(ascii, header, vertex);
    ascii.finish();
    return result;
  }
  BinaryBody binary(path, body, needs_swap(header.format));
  return read(binary, header, vertex);
}

// ---- writing

void check_attribute_names(const std::string& path, const PointCloud& cloud) {
  for (const NamedAttribute& attribute : cloud.attributes()) {
    const std::string& name = attribute.name;
    const bool blank = name.empty() || std::ranges::any_of(name, [](char c) {
                         return std::isspace(static_cast<unsigned char>(c));
                       });
    if (blank || name == "x" || name == "y" || name == "z") {
      throw Error(path, fmt::format("attribute '{}'", name),
                  "is not a valid PLY property name (non-empty, no spaces, not x, y or z)");
    }
  }
}

// A re-centred cloud (origin != 0) is written in double, origin + (x, y, z): its original
// coordinates, where float would lose them.
bool has_origin(const PointCloud& cloud) { return !cloud.origin.isZero(); }

std::vector<double> world_axis(const PointCloud& cloud, int axis) {
  const std::vector<float>& relative = axis == 0 ? cloud.x : axis == 1 ? cloud.y : cloud.z;
  std::vector<double> world(relative.size());
  for (std::size_t i = 0; i < relative.size(); ++i)
    world[i] = cloud.origin[axis] + double(relative[i]);
  return world;
}

std::string header_text(const PointCloud& cloud, PlyFormat format) {
  std::string header = fmt::format(
      "ply\nformat {0} 1.0\ncomment generated by glint\nelement vertex {1}\n"
      "property {2} x\nproperty {2} y\nproperty {2} z\n",
      kFormatNames[static_cast<int>(format)], cloud.size(), has_origin(cloud) ? "double" : "float");
  for (const NamedAttribute& attribute : cloud.attributes()) {
    header +=
        fmt::format("property {} {}\n", type_name(scalar_of(attribute.values)), attribute.name);
  }
  return header + "end_header\n";
}

void write_binary_body(std::ostream& out, const PointCloud& cloud, bool swap) {
  struct Column {
    const char* bytes;
    std::size_t size;
  };
  std::vector<Column> columns;
  std::vector<double> world[3];
  if (has_origin(cloud)) {
    for (int a = 0; a < 3; ++a) {
      world[a] = world_axis(cloud, a);
      columns.push_back({reinterpret_cast<const char*>(world[a].data()), sizeof(double)});
    }
  } else {
    for (const std::vector<float>* axis : {&cloud.x, &cloud.y, &cloud.z}) {
      columns.push_back({reinterpret_cast<const char*>(axis->data()), sizeof(float)});
    }
  }
  for (const NamedAttribute& attribute : cloud.attributes()) {
    columns.push_back({column_bytes(attribute.values), size_of(scalar_of(attribute.values))});
  }
  std::string buffer;
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    for (const Column& column : columns) {
      buffer.resize(buffer.size() + column.size);
      copy_value(column.bytes + i * column.size, buffer.data() + buffer.size() - column.size,
                 column.size, swap);
    }
    flush_buffer(buffer, out);
  }
  flush_buffer(buffer, out, 0);
}

void write_ascii_body(std::ostream& out, const PointCloud& cloud) {
  std::string buffer;
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    if (has_origin(cloud)) {
      for (int a = 0; a < 3; ++a) {
        const float relative = a == 0 ? cloud.x[i] : a == 1 ? cloud.y[i] : cloud.z[i];
        fmt::format_to(std::back_inserter(buffer), "{} ", cloud.origin[a] + double(relative));
      }
    } else {
      for (const float value : {cloud.x[i], cloud.y[i], cloud.z[i]}) {
        append_value(buffer, value);
        buffer += ' ';
      }
    }
    for (const NamedAttribute& attribute : cloud.attributes()) {
      append_value(buffer, attribute.values, i);
      buffer += ' ';
    }
    buffer.back() = '\n';
    flush_buffer(buffer, out);
  }
  flush_buffer(buffer, out, 0);
}

}  // namespace

PointCloud read_ply(const std::string& path) {
  return read_with_body(path, [&](auto& body, const Header& header, const Element& vertex) {
    return read_body(path, body, header, vertex);
  });
}

PlyMesh read_ply_mesh(const std::string& path) {
  return read_with_body(path, [&](auto& body, const Header& header, const Element& vertex) {
    return read_mesh_body(path, body, header, vertex);
  });
}

void write_ply(const std::string& path, const PointCloud& cloud, PlyFormat format) {
  check_attribute_names(path, cloud);
  AtomicFile file(path);
  file.stream() << header_text(cloud, format);
  if (format == PlyFormat::ascii) {
    write_ascii_body(file.stream(), cloud);
  } else {
    write_binary_body(file.stream(), cloud, needs_swap(format));
  }
  file.commit();
}

}  // namespace glint::io
