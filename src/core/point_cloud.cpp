#include "core/point_cloud.h"

#include <algorithm>

#include "core/error.h"

namespace glint {

std::size_t column_size(const AttributeColumn& column) {
  return std::visit([](const auto& values) { return values.size(); }, column);
}

double column_value(const AttributeColumn& column, std::size_t i) {
  return std::visit([i](const auto& values) { return static_cast<double>(values[i]); }, column);
}

void PointCloud::resize(std::size_t n) {
  x.resize(n);
  y.resize(n);
  z.resize(n);
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

}  // namespace glint
