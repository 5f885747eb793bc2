#pragma once
// Photometric fit of a segment's specular lobe (glint's addition to paper 1 §3.6): with the
// lights, the voxel normals and eq. (6)'s image formation,
//   B_vk = kd_v / pi * sum_l L_l cos(theta_i,l)
//          + ks * sum_l exp(gamma_l) / N_l * L_l cos(theta_i,l)
// the diffuse term is the same for every observation k of voxel v, so subtracting each voxel's
// mean observation removes the unknown, spatially varying kd_v. What is left is linear in ks:
// for a given alpha, ks per channel is a least-squares slope in closed form, and alpha is the
// one-dimensional minimiser of the remaining squared error (a log-spaced scan, then golden-
// section search). Observations with a clipped channel bound the prediction there from below
// (a censored fit): a bound the lobe falls short of adds its shortfall squared. The HemiCNN's
// estimate stands where the lobe explains too little of the observations' variation (a matte
// segment, too few views of its highlights, or a lobe that falls short of the clipped ones).
#include <Eigen/Core>
#include <limits>
#include <optional>
#include <vector>

#include "reflectance/light_incidence.h"
#include "reflectance/observation.h"
#include "render/scene.h"

namespace glint::reflectance {

struct SpecularFitParams {
  float alpha_min = 0.01f;  // the searched roughness range
  float alpha_max = 0.5f;
  int scan_steps = 12;    // log-spaced alphas tried before the golden-section refinement
  int refine_steps = 10;  // golden-section iterations (each shrinks the bracket by 0.618)
  // The fitted lobe must explain at least this fraction of the observations' variation about
  // their voxels' means, or the fit is not used.
  float min_explained = 0.2f;
  // Observations with a channel at or above this radiance are clipped by the sensor (a
  // highlight's peak often is): bounds, not data. The pipeline sets it from the exposure.
  float saturated_radiance = std::numeric_limits<float>::infinity();
  // Clipped observations as lower bounds of the prediction in their clipped channels (false:
  // left out of the fit altogether).
  bool clipped_as_bounds = true;
};

// One voxel's stored observations, its surface point and the lights that reach it (a shadowed
// light casts no highlight; the indirect light's diffuse part is the same for every observation
// of the voxel, so the fit's centring removes it).
struct FitVoxel {
  const Observation* observations = nullptr;
  int count = 0;
  Eigen::Vector3f position = Eigen::Vector3f::Zero();
  Eigen::Vector3f normal = Eigen::Vector3f::UnitZ();
  PointLighting lighting;
};

struct SpecularFit {
  Eigen::Vector3f ks = Eigen::Vector3f::Zero();  // per channel, >= 0
  float alpha = 0.1f;
  // 1 - residual (bounds' shortfalls included) / variation about the voxel means, in [0, 1]
  float explained = 0.0f;
  int observations = 0;  // data (unclipped observations from above the surface) in the fit
};

// Fits (ks, alpha) to the observations of `voxels` (those from above the surface and not
// saturated; a voxel needs two). nullopt when nothing varies, no light reaches any voxel, or the
// lobe explains less than params.min_explained.
std::optional<SpecularFit> fit_specular(const std::vector<FitVoxel>& voxels,
                                        const std::vector<render::PointLight>& lights,
                                        const SpecularFitParams& params = {});

}  // namespace glint::reflectance
