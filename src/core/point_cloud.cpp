#include "core/point_cloud.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <exception>
#include <limits>
#include <string>

#include "core/error.h"
#include "core/limits.h"

namespace glint {

std::size_t column_size(const AttributeColumn& column) {
  return std::visit([](const auto& values) { return values.size(); }, column);
}

double column_value(const AttributeColumn& column, std::size_t i) {
  return std::visit([i](const auto& values) { return static_cast<double>(values[i]); }, column);
}

void PointCloud::resize(std::size_t n) {
  try {
    x.resize(n);
    y.resize(n);
    z.resize(n);
  } catch (const std::exception&) {  // std::bad_alloc, or std::length_error beyond max_size()
    limits::throw_out_of_memory("a cloud of " + std::to_string(n) + " points",
                                3.0 * double(n) * sizeof(float));
  }
  for (auto& attribute : attributes_) {
    std::visit([n](auto& values) { values.resize(n); }, attribute.values);
  }
}

void PointCloud::reserve(std::size_t n) {
  x.reserve(n);
  y.reserve(n);
  z.reserve(n);
}

void PointCloud::push_back(float px, float py, float pz) {
  x.push_back(px);
  y.push_back(py);
  z.push_back(pz);
}

const AttributeColumn* PointCloud::find(const std::string& name) const {
  for (const auto& attribute : attributes_) {
    if (attribute.name == name) return &attribute.values;
  }
  return nullptr;
}

void PointCloud::set(const std::string& name, AttributeColumn values) {
  if (column_size(values) != size()) {
    throw Error("", "attribute '" + name + "'",
                "has " + std::to_string(column_size(values)) + " values for " +
                    std::to_string(size()) + " points");
  }
  for (auto& attribute : attributes_) {
    if (attribute.name == name) {
      attribute.values = std::move(values);
      return;
    }
  }
  attributes_.push_back({name, std::move(values)});
}

void PointCloud::remove(const std::string& name) {
  std::erase_if(attributes_, [&](const NamedAttribute& a) { return a.name == name; });
}

namespace {

template <class T>
std::vector<T> select_values(const std::vector<T>& values, const std::vector<bool>& keep) {
  std::vector<T> kept;
  for (std::size_t i = 0; i < values.size(); ++i) {
    if (keep[i]) kept.push_back(values[i]);
  }
  return kept;
}

}  // namespace

PointCloud PointCloud::select(const std::vector<bool>& keep) const {
  if (keep.size() != size()) {
    throw Error("", "selection mask",
                "has " + std::to_string(keep.size()) + " entries for " + std::to_string(size()) +
                    " points");
  }
  PointCloud out;
  out.origin = origin;
  out.x = select_values(x, keep);
  out.y = select_values(y, keep);
  out.z = select_values(z, keep);
  for (const auto& attribute : attributes_) {
    out.attributes_.push_back(
        {attribute.name,
         std::visit(
             [&](const auto& values) { return AttributeColumn(select_values(values, keep)); },
             attribute.values)});
  }
  return out;
}

void set_positions(PointCloud& cloud, const double* x, const double* y, const double* z,
                   std::size_t n, const std::string& file) {
  const double* axes[3] = {x, y, z};
  Eigen::Vector3d lower = Eigen::Vector3d::Constant(std::numeric_limits<double>::infinity());
  Eigen::Vector3d upper = -lower;
  for (std::size_t i = 0; i < n; ++i) {
    for (int a = 0; a < 3; ++a) {
      const double value = axes[a][i];
      if (!std::isfinite(value))
        throw Error(file, "vertex " + std::to_string(i), "non-finite coordinate");
      lower[a] = std::min(lower[a], value);
      upper[a] = std::max(upper[a], value);
    }
  }
  Eigen::Vector3d origin = Eigen::Vector3d::Zero();
  if (n > 0) {
    const Eigen::Vector3d centre = 0.5 * lower + 0.5 * upper;  // halves first: no overflow
    const double distance = centre.cwiseAbs().maxCoeff();
    if (distance > kRecentreBeyond && distance > (upper - lower).maxCoeff())
      origin = centre.array().round();
  }
  cloud.resize(n);
  cloud.origin = origin;
  float* out[3] = {cloud.x.data(), cloud.y.data(), cloud.z.data()};
  for (std::size_t i = 0; i < n; ++i) {
    for (int a = 0; a < 3; ++a) {
      const double relative = axes[a][i] - origin[a];
      if (!std::isfinite(static_cast<float>(relative)))  // rounds to at most FLT_MAX
        throw Error(file, "vertex " + std::to_string(i),
                    fmt::format("coordinate {} is {:g} from the cloud's origin {}: outside the "
                                "float range",
                                axes[a][i], relative, origin[a]));
      out[a][i] = static_cast<float>(relative);
    }
  }
}

}  // namespace glint
