#pragma once
// The feature files of the ABC dataset (Koch et al. 2019): beside each model's `trimesh` OBJ, a
// `features` YAML lists the B-rep's curves as runs of the mesh's vertex indices, each flagged
// sharp or not. For an ABC mesh these flags are the ground truth ABC-trained detectors learn
// from (a vertex on a sharp curve is sharp), so `glint edges label --abc-features` takes them
// instead of the mesh's dihedral angles.
#include <Eigen/Core>
#include <string>
#include <vector>

namespace glint::cad {

struct EdgeClasses;

// The curves of `path` flagged `sharp: true`, as segments between consecutive entries of each
// curve's `vert_indices` (0-based into the OBJ's vertices, `vertices`); `sharp` counts those
// curves, `smooth` the others (the lengths are left to the caller, who may cut them). Throws
// glint::Error(path, element, reason) for a missing or unparsable file, a missing `curves`
// list, a curve without `sharp` or `vert_indices`, or an index outside the mesh.
EdgeClasses read_abc_sharp_curves(const std::string& path,
                                  const std::vector<Eigen::Vector3d>& vertices);

}  // namespace glint::cad
