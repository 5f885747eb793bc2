#include "render/ply_mesh.h"

#include <fmt/format.h>

#include <bit>
#include <optional>
#include <string_view>
#include <vector>

#include "core/error.h"
#include "io/codec.h"
#include "io/file_bytes.h"

namespace glint::render {
namespace {

using io::Scalar;

struct Property {
  std::string name;
  Scalar type = Scalar::float32;      // for lists: the item type
  std::optional<Scalar> list_length;  // for lists: the length prefix type
};

struct Element {
  std::string name;
  std::size_t count = 0;
  std::vector<Property> properties;
};

enum class Encoding { ascii, little_endian, big_endian };

struct Header {
  Encoding encoding = Encoding::ascii;
  std::vector<Element> elements;
  std::size_t body_offset = 0;
};

std::optional<Scalar> parse_type(std::string_view name) {
  constexpr std::string_view kNames[] = {"char", "uchar", "short", "ushort",
                                         "int",  "uint",  "float", "double"};
  constexpr std::string_view kAliases[] = {"int8",  "uint8",  "int16",   "uint16",
                                           "int32", "uint32", "float32", "float64"};
  for (int t = 0; t < 8; ++t) {
    if (name == kNames[t] || name == kAliases[t]) return static_cast<Scalar>(t);
  }
  return std::nullopt;
}

Header parse_header(const std::string& path, const std::string& bytes) {
  Header header;
  std::size_t position = 0;
  bool first = true;
  while (true) {
    const std::size_t end = bytes.find('\n', position);
    if (end == std::string::npos) throw Error(path, "header", "no end_header line");
    std::string_view line(bytes.data() + position, end - position);
    position = end + 1;
    if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
    const std::vector<std::string_view> words = io::split_words(line);
    if (first) {
      if (words.size() != 1 || words[0] != "ply") throw Error(path, "header", "not a PLY file");
      first = false;
      continue;
    }
    if (words.empty() || words[0] == "comment" || words[0] == "obj_info") continue;
    if (words[0] == "end_header") break;
    if (words[0] == "format" && words.size() >= 2) {
      if (words[1] == "ascii")
        header.encoding = Encoding::ascii;
      else if (words[1] == "binary_little_endian")
        header.encoding = Encoding::little_endian;
      else if (words[1] == "binary_big_endian")
        header.encoding = Encoding::big_endian;
      else
        throw Error(path, "header", fmt::format("unknown format '{}'", words[1]));
    } else if (words[0] == "element" && words.size() == 3) {
      Element element{std::string(words[1]), 0, {}};
      if (!io::parse_count(words[2], element.count))
        throw Error(path, "header", fmt::format("bad element count '{}'", words[2]));
      header.elements.push_back(std::move(element));
    } else if (words[0] == "property" && !header.elements.empty()) {
      Property property;
      if (words.size() == 5 && words[1] == "list") {
        property.list_length = parse_type(words[2]);
        const std::optional<Scalar> item = parse_type(words[3]);
        if (!property.list_length || !item)
          throw Error(path, "header", fmt::format("bad list property '{}'", line));
        property.type = *item;
        property.name = words[4];
      } else if (words.size() == 3) {
        const std::optional<Scalar> type = parse_type(words[1]);
        if (!type) throw Error(path, "header", fmt::format("unknown type '{}'", words[1]));
        property.type = *type;
        property.name = words[2];
      } else {
        throw Error(path, "header", fmt::format("bad property line '{}'", line));
      }
      header.elements.back().properties.push_back(std::move(property));
    } else {
      throw Error(path, "header", fmt::format("unexpected line '{}'", line));
    }
  }
  header.body_offset = position;
  return header;
}

// Reads the values of one element's records one at a time, in either encoding.
class RecordReader {
 public:
  RecordReader(const std::string& path, const std::string& bytes, const Header& header)
      : path_(path),
        at_(bytes.data() + header.body_offset),
        end_(bytes.data() + bytes.size()),
        tokens_(at_, end_),
        encoding_(header.encoding) {}

  double value(Scalar type, const std::string& element) {
    if (encoding_ == Encoding::ascii) {
      double number = 0;
      const std::string_view token = tokens_.next();
      if (token.empty() || !io::parse_number(token, number))
        throw Error(path_, element, "truncated or malformed ascii data");
      return number;
    }
    const std::size_t size = io::size_of(type);
    if (static_cast<std::size_t>(end_ - at_) < size) throw Error(path_, element, "truncated data");
    const bool swap =
        (encoding_ == Encoding::big_endian) != (std::endian::native == std::endian::big);
    const double number = io::decode(type, at_, swap);
    at_ += size;
    return number;
  }

 private:
  const std::string& path_;
  const char* at_;
  const char* end_;
  io::Tokens tokens_;
  Encoding encoding_;
};

int find_property(const Element& element, std::string_view name) {
  for (std::size_t p = 0; p < element.properties.size(); ++p) {
    if (element.properties[p].name == name) return static_cast<int>(p);
  }
  return -1;
}

}  // namespace

TriangleMesh read_ply_mesh(const std::string& path) {
  const std::string bytes = io::read_file_bytes(path);
  const Header header = parse_header(path, bytes);
  RecordReader reader(path, bytes, header);
  TriangleMesh mesh;
  bool has_faces = false;
  for (const Element& element : header.elements) {
    const int x = find_property(element, "x"), y = find_property(element, "y"),
              z = find_property(element, "z");
    int list = find_property(element, "vertex_indices");
    if (list < 0) list = find_property(element, "vertex_index");
    if (element.name == "vertex" && (x < 0 || y < 0 || z < 0))
      throw Error(path, "vertex", "needs x, y and z properties");
    if (element.name == "face" && list < 0)
      throw Error(path, "face", "needs a vertex_indices list");
    has_faces = has_faces || (element.name == "face" && element.count > 0);
    std::vector<int> polygon;
    for (std::size_t r = 0; r < element.count; ++r) {
      Eigen::Vector3f position = Eigen::Vector3f::Zero();
      for (std::size_t p = 0; p < element.properties.size(); ++p) {
        const Property& property = element.properties[p];
        if (!property.list_length) {
          const double value = reader.value(property.type, element.name);
          const int index = static_cast<int>(p);
          if (index == x) position.x() = float(value);
          if (index == y) position.y() = float(value);
          if (index == z) position.z() = float(value);
          continue;
        }
        const auto length =
            static_cast<std::size_t>(reader.value(*property.list_length, element.name));
        polygon.clear();
        for (std::size_t i = 0; i < length; ++i)
          polygon.push_back(static_cast<int>(reader.value(property.type, element.name)));
        if (element.name != "face" || static_cast<int>(p) != list) continue;
        for (std::size_t i = 2; i < polygon.size(); ++i)
          mesh.triangles.emplace_back(polygon[0], polygon[i - 1], polygon[i]);
      }
      if (element.name == "vertex") mesh.vertices.push_back(position);
    }
  }
  if (!has_faces || mesh.triangles.empty()) throw Error(path, "face", "the mesh has no faces");
  const int vertex_count = static_cast<int>(mesh.vertices.size());
  for (std::size_t t = 0; t < mesh.triangles.size(); ++t) {
    if (mesh.triangles[t].minCoeff() < 0 || mesh.triangles[t].maxCoeff() >= vertex_count)
      throw Error(path, fmt::format("triangle {}", t), "vertex index out of range");
  }
  return mesh;
}

}  // namespace glint::render
