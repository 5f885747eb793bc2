#pragma once
// Random mechanical parts built the way CAD parts are built, on the OpenCASCADE kernel: a base
// solid (block, plate, extruded random profile, turned = revolved random profile, or a
// cylinder), then holes, blind holes, pockets, slots and bosses by booleans, fillets and
// chamfers of random radii on random edges, optionally a shell (hollowed with its top face
// removed). Open variants, as real data has them: cut open by a plane (the part's surface on
// one side, no cap) or with some faces removed.
//
// Every kernel operation that fails (Standard_Failure, not done, an invalid result, or past
// its time limit) is skipped and recorded, so a part is always produced; the recipe JSON says
// what was built. Same (params, index) -> same part on every run and thread count, unless an
// operation hit the time limit (recorded as "timed_out" in the recipe). Thread-safe: the
// kernel's modelling algorithms are not reentrant, so random_part and cut_open take turns.
#include <Eigen/Core>
#include <TopoDS_Shape.hxx>
#include <array>
#include <cstdint>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

namespace glint::cad {

enum class PartRecipe { block, plate, extrusion, turned, cylinder };
const std::vector<std::string>& part_recipe_names();
// Throws glint::Error("--recipes", name, ...) listing the known names.
PartRecipe parse_part_recipe(const std::string& name);

enum class OpenKind { closed, plane_cut, faces_removed };

struct PartParams {
  std::uint64_t seed = 1;
  std::vector<PartRecipe> recipes;         // drawn uniformly; empty = every recipe
  int max_features = 5;                    // holes, pockets, slots, bosses: 0..max per part
  double fillet_probability = 0.6;         // share of parts with 1-6 filleted edges
  double chamfer_probability = 0.3;        // share of parts with 1-4 chamfered edges
  double shell_probability = 0.15;         // share of parts hollowed out (top face removed)
  double plane_cut_probability = 0.0;      // share of parts cut open by a random plane
  double faces_removed_probability = 0.0;  // share of parts with 1-2 faces removed
  double operation_time_limit_s = 20.0;    // per kernel operation; a slower one is skipped
};

// Throws glint::Error("part parameters", key, reason).
void check_part_params(const PartParams& params);

struct Part {
  TopoDS_Shape shape;     // a solid, or a shell / compound of faces when opened
  nlohmann::json recipe;  // seed, index, base, operations done and skipped, opening
};

// Part number `index` of the stream seeded by params.seed. The opening (plane cut or faces
// removed) draws from its own stream, so the same index gives the same part whether or not it
// is opened.
Part random_part(const PartParams& params, std::uint64_t index);

// The surface of `shape` on the positive side of the plane through `point` with normal
// `normal`, without a cap: the cut edges become open borders. Throws glint::Error when the
// kernel fails or nothing remains.
TopoDS_Shape cut_open(const TopoDS_Shape& shape, const double point[3], const double normal[3]);

// The lowest and highest corners of the shape's axis-aligned bounding box. Throws
// glint::Error("shape", "bounding box", ...) when the box is empty or unbounded.
std::array<Eigen::Vector3d, 2> shape_bounds(const TopoDS_Shape& shape);

}  // namespace glint::cad
