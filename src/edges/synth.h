#pragma once
// Procedural labelled training clouds for BoundED (the thesis' Default/ABC training sets are not
// public). Every cloud is one randomly sized, rotated shape, tessellated into a triangle mesh
// whose edges give the exact labels:
//   sharp edge (1)  mesh edge whose two faces' normals differ by >= sharp_angle_deg, or an edge
//                   shared by more than two faces;
//   boundary (2)    mesh edge with a single face (open sheets, rims, holes);
// a point is sharp within `band` x the local point spacing of a sharp edge (the Bazazian / PCEDNet
// convention: a band about one point wide) and boundary within `boundary_band` spacings of a
// boundary (wider, so that the outermost row of a random sample is labelled: a sample's last
// points lie on average half a spacing inside the true border); boundary wins where both apply.
// Curved surfaces are tessellated finely enough that their own edges stay far below the angle.
//
// Samplings: uniform random on the surface (Bazazian's clouds), or ABC-like, where a share of
// the points lies exactly on the feature edges as mesh vertices do in ABC clouds; the density
// may vary across the shape. Noise: Gaussian, sigma a multiple of the spacing, labels from the
// clean position; outliers (as in Bazazian's noisy clouds) are labelled at their new position.
#include <cstdint>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "core/point_cloud.h"

namespace glint::edges {

enum class SynthShape {
  crease,        // two planar sheets meeting at a dihedral angle (sharp crease, open rims)
  bend,          // the same with a shallow angle below the sharp threshold (no crease label)
  box,           // closed box of random proportions
  open_box,      // box without its lid (rim = boundary)
  thin_wall,     // box one to five point spacings thick
  fractal_cube,  // cube with random voxel bumps and notches (Bazazian's CubeFractal*)
  stairs,        // staircase block (StairsCube)
  cylinder,      // closed cylinder (circular sharp edges)
  tube,          // open cylinder (circular boundaries)
  cone,          // closed cone
  frustum,       // closed truncated cone
  sheet,         // planar rectangle
  wavy_sheet,    // smooth height field
  disc,          // planar disc
  annulus,       // disc with a hole
  holed_sheet,   // tiles of a plane with round holes
  sphere,        // closed, no features
  hemisphere,    // open dome
  curved_sheet,  // part of a cylinder wall
};

const std::vector<std::string>& synth_shape_names();
// Throws glint::Error("--shapes", name, ...) listing the known names.
SynthShape parse_synth_shape(const std::string& name);

struct SynthParams {
  std::uint64_t seed = 1;
  std::vector<SynthShape> shapes;  // drawn uniformly; empty = every shape
  int min_points = 4000;           // points per cloud, log-uniform in the range
  int max_points = 40000;
  std::vector<double> noise_levels{0.0, 0.0, 0.02, 0.05, 0.1, 0.2};  // sigma / spacing, one drawn
  double outlier_probability = 0.15;  // share of clouds that get 2-15 % outliers
  double abc_probability = 0.3;       // share of clouds sampled ABC-like
  double gradient_probability = 0.3;  // share of clouds with a density gradient
  double band = 0.3;                  // sharp label band, in local point spacings
  double boundary_band = 0.6;         // boundary label band, in local point spacings
  double sharp_angle_deg = 25.0;      // normal change that makes a crease sharp
};

// Throws glint::Error("synth parameters", key, reason) for inconsistent parameters.
void check_synth_params(const SynthParams& params);

struct SynthCloud {
  PointCloud cloud;            // x y z and uchar "label" (0 non-edge, 1 sharp, 2 boundary)
  nlohmann::json description;  // shape, sampling, noise, spacing, label counts
};

// Cloud number `index` of the stream seeded by params.seed; the same (params, index) always
// gives the same cloud, whatever the thread count.
SynthCloud synthesize_cloud(const SynthParams& params, std::uint64_t index);

}  // namespace glint::edges
