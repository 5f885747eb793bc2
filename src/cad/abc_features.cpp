#include "cad/abc_features.h"

#include <fmt/format.h>
#include <yaml-cpp/yaml.h>

#include <filesystem>

#include "cad/sample.h"
#include "core/error.h"

namespace glint::cad {

EdgeClasses read_abc_sharp_curves(const std::string& path,
                                  const std::vector<Eigen::Vector3d>& vertices) {
  if (!std::filesystem::is_regular_file(path)) throw Error(path, "", "no such features file");
  YAML::Node root;
  try {
    root = YAML::LoadFile(path);
  } catch (const YAML::Exception& e) {
    throw Error(path, fmt::format("line {}", e.mark.line + 1), "not YAML: " + e.msg);
  }
  const YAML::Node curves = root.IsMap() ? root["curves"] : YAML::Node();
  if (!curves.IsSequence())
    throw Error(path, "curves", "missing: not an ABC features file (a `curves` list)");

  EdgeClasses classes;
  for (std::size_t c = 0; c < curves.size(); ++c) {
    const YAML::Node curve = curves[c];
    const std::string where = fmt::format("curves[{}]", c);
    // A missing key gives an undefined node, on which any other query throws.
    const YAML::Node sharp = curve.IsMap() ? curve["sharp"] : YAML::Node();
    const YAML::Node indices = curve.IsMap() ? curve["vert_indices"] : YAML::Node();
    if (!sharp.IsDefined() || !sharp.IsScalar()) throw Error(path, where + ".sharp", "missing");
    if (!indices.IsDefined() || !indices.IsSequence())
      throw Error(path, where + ".vert_indices", "missing");
    bool is_sharp = false;
    try {
      is_sharp = sharp.as<bool>();
    } catch (const YAML::Exception&) {
      throw Error(path, where + ".sharp", "is not true or false");
    }
    if (!is_sharp) {
      ++classes.smooth;
      continue;
    }
    ++classes.sharp;
    long previous = -1;
    for (std::size_t k = 0; k < indices.size(); ++k) {
      const std::string element = fmt::format("{}.vert_indices[{}]", where, k);
      long index = -1;
      try {
        index = indices[k].as<long>();
      } catch (const YAML::Exception&) {
        throw Error(path, element, "is not an integer");
      }
      if (index < 0 || index >= long(vertices.size()))
        throw Error(path, element,
                    fmt::format("is not a vertex of the mesh ({} vertices)", vertices.size()));
      if (previous >= 0 && previous != index) {
        classes.segments.push_back(
            {vertices[std::size_t(previous)], vertices[std::size_t(index)], edges::kLabelSharp});
      }
      previous = index;
    }
    if (indices.size() == 1) {  // a curve of one vertex labels that vertex
      const Eigen::Vector3d& a = vertices[std::size_t(previous)];
      classes.segments.push_back({a, a, edges::kLabelSharp});
    }
  }
  return classes;
}

}  // namespace glint::cad
