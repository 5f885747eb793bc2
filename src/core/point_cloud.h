#pragma once
// PointCloud: positions as structure of arrays plus named, typed optional per-point attributes
// (labels, normals, colours, probabilities, anything a PLY vertex property can hold).
//
// Positions are float (metres or the file's own unit) relative to `origin` (double): a point's
// position is origin + (x, y, z). Readers re-centre a cloud that lies far from 0 (a scan at
// 10^7 m) on an integer origin before its coordinates become float (set_positions below), so
// features see the same floats as for the cloud at 0, and writers add the origin back.
#include <Eigen/Core>
#include <cstddef>
#include <cstdint>
#include <string>
#include <variant>
#include <vector>

namespace glint {

// One attribute column; the alternative held is the attribute's scalar type.
using AttributeColumn =
    std::variant<std::vector<std::int8_t>, std::vector<std::uint8_t>, std::vector<std::int16_t>,
                 std::vector<std::uint16_t>, std::vector<std::int32_t>, std::vector<std::uint32_t>,
                 std::vector<float>, std::vector<double>>;

struct NamedAttribute {
  std::string name;
  AttributeColumn values;
};

// Number of elements in a column, whatever its type.
std::size_t column_size(const AttributeColumn& column);
// Element i of a column converted to double.
double column_value(const AttributeColumn& column, std::size_t i);

class PointCloud {
 public:
  std::vector<float> x, y, z;
  Eigen::Vector3d origin = Eigen::Vector3d::Zero();  // added to (x, y, z) on output

  std::size_t size() const { return x.size(); }
  bool empty() const { return x.empty(); }
  void resize(std::size_t n);
  void reserve(std::size_t n);
  void push_back(float px, float py, float pz);
  Eigen::Vector3f point(std::size_t i) const { return {x[i], y[i], z[i]}; }

  // Attributes keep their insertion order (it is the order they are written in).
  const std::vector<NamedAttribute>& attributes() const { return attributes_; }
  bool has(const std::string& name) const { return find(name) != nullptr; }
  const AttributeColumn* find(const std::string& name) const;

  // Typed access: nullptr when absent or stored with another type.
  template <class T>
  const std::vector<T>* get(const std::string& name) const {
    const AttributeColumn* column = find(name);
    return column ? std::get_if<std::vector<T>>(column) : nullptr;
  }

  // Adds or replaces an attribute; throws glint::Error when its length differs from size().
  void set(const std::string& name, AttributeColumn values);
  void remove(const std::string& name);

  // Keeps the points whose mask entry is true (positions and every attribute).
  PointCloud select(const std::vector<bool>& keep) const;

 private:
  std::vector<NamedAttribute> attributes_;
};

// Largest |coordinate - origin| edge features accept, in the cloud's unit (1e9): beyond it
// squared distances and covariance sums overflow float (a coordinate of 1e37 gave NaN
// probabilities). Checked by edges::compute_features, not by the readers.
inline constexpr double kMaxCloudCoordinate = 1e9;
// A cloud whose bounding-box centre is farther from 0 than this (in its unit) and than its own
// size is re-centred on read: float keeps 1 mm steps up to about 1e4.
inline constexpr double kRecentreBeyond = 1e4;

// Makes `cloud` hold the n points (x[i], y[i], z[i]) given in double: when the cloud's centre
// lies farther from 0 than kRecentreBeyond and than the cloud's own size, it is re-centred on
// the integer point nearest its bounding box's centre (float coordinates far from 0 then
// round-trip exactly); otherwise origin = 0 and positions are as given. Attributes are
// untouched (the cloud must hold n points or none). Throws glint::Error(file, "vertex i", ...)
// for a non-finite coordinate or one that does not fit a float relative to the origin.
void set_positions(PointCloud& cloud, const double* x, const double* y, const double* z,
                   std::size_t n, const std::string& file);

}  // namespace glint
