#pragma once
// JSON reports and small JSON files (models, run summaries), written atomically and pretty
// printed with two-space indentation.
#include <nlohmann/json.hpp>
#include <string>

namespace glint::io {

void write_json(const std::string& path, const nlohmann::json& value);
// Parses a JSON file; throws glint::Error naming the file and the parse position on failure.
nlohmann::json read_json(const std::string& path);
// A 3-vector (an Eigen::Vector3f or Vector3d) as the JSON array [x, y, z].
template <class Vector3>
nlohmann::json vector_json(const Vector3& v) {
  return {v.x(), v.y(), v.z()};
}

}  // namespace glint::io
