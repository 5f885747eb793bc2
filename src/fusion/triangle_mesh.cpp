#include "fusion/triangle_mesh.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <ostream>
#include <vector>

#include "core/error.h"
#include "core/parallel.h"
#include "io/atomic_file.h"

namespace glint::fusion {

double surface_area(const TriangleMesh& mesh) {
  double area = 0;
  for (const Eigen::Vector3i& t : mesh.triangles) {
    const Eigen::Vector3d a = mesh.vertices[t[0]].cast<double>();
    area += 0.5 * (mesh.vertices[t[1]].cast<double>() - a)
                      .cross(mesh.vertices[t[2]].cast<double>() - a)
                      .norm();
  }
  return area;
}

double enclosed_volume(const TriangleMesh& mesh) {
  double volume = 0;
  for (const Eigen::Vector3i& t : mesh.triangles) {
    volume += mesh.vertices[t[0]].cast<double>().dot(
                  mesh.vertices[t[1]].cast<double>().cross(mesh.vertices[t[2]].cast<double>())) /
              6.0;
  }
  return volume;
}

unsigned char linear_to_srgb8(float linear) {
  const float c = std::clamp(linear, 0.0f, 1.0f);
  const float encoded = c <= 0.0031308f ? 12.92f * c : 1.055f * std::pow(c, 1.0f / 2.4f) - 0.055f;
  return static_cast<unsigned char>(std::lround(encoded * 255.0f));
}

namespace {

// Writes `count` fixed-size binary records, packed by pack(i, record) in parallel a chunk at a
// time: a mesh of millions of vertices took longer to encode (sRGB) and to buffer whole (page
// faults on a buffer of hundreds of MB) than to write.
template <class Pack>
void write_records(std::ostream& out, std::size_t count, std::size_t record_bytes, Pack&& pack) {
  constexpr std::size_t kChunkRecords = std::size_t{1} << 16;
  std::vector<char> buffer(std::min(count, kChunkRecords) * record_bytes);
  for (std::size_t first = 0; first < count; first += kChunkRecords) {
    const std::size_t records = std::min(kChunkRecords, count - first);
    parallel_for(records,
                 [&](std::size_t i) { pack(first + i, buffer.data() + i * record_bytes); });
    out.write(buffer.data(), static_cast<std::streamsize>(records * record_bytes));
  }
}

}  // namespace

void write_mesh_ply(const std::string& path, const TriangleMesh& mesh) {
  io::AtomicFile file(path);
  std::ostream& out = file.stream();
  const bool with_colour = mesh.colours.size() == mesh.vertices.size();
  out << "ply\nformat binary_little_endian 1.0\ncomment glint: marching cubes of a voxel-hashed "
         "TSDF\n";
  for (const std::string& comment : mesh.comments) {
    if (comment.find_first_of("\r\n") != std::string::npos)
      throw Error(path, "comment", "must be a single line: " + comment);
    out << "comment " << comment << "\n";
  }
  out << "element vertex " << mesh.vertices.size() << "\n"
      << "property float x\nproperty float y\nproperty float z\n";
  if (with_colour) out << "property uchar red\nproperty uchar green\nproperty uchar blue\n";
  for (const auto& [name, values] : mesh.vertex_properties) {
    if (values.size() != mesh.vertices.size())
      throw Error(path, name,
                  "has " + std::to_string(values.size()) + " values for " +
                      std::to_string(mesh.vertices.size()) + " vertices");
    out << "property float " << name << "\n";
  }
  out << "element face " << mesh.triangles.size() << "\n"
      << "property list uchar int vertex_indices\nend_header\n";
  const std::size_t colour_bytes = with_colour ? 3 : 0;
  const std::size_t vertex_bytes = 12 + colour_bytes + 4 * mesh.vertex_properties.size();
  write_records(out, mesh.vertices.size(), vertex_bytes, [&](std::size_t i, char* record) {
    std::memcpy(record, mesh.vertices[i].data(), 12);
    if (with_colour) {
      for (int c = 0; c < 3; ++c)
        record[12 + c] = static_cast<char>(linear_to_srgb8(mesh.colours[i][c]));
    }
    for (std::size_t k = 0; k < mesh.vertex_properties.size(); ++k)
      std::memcpy(record + 12 + colour_bytes + 4 * k, &mesh.vertex_properties[k].second[i], 4);
  });
  write_records(out, mesh.triangles.size(), 13, [&](std::size_t i, char* record) {
    record[0] = 3;
    std::memcpy(record + 1, mesh.triangles[i].data(), 12);
  });
  file.commit();
}

}  // namespace glint::fusion
