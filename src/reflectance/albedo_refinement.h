#pragma once
// Albedo refinement (paper 1 §3.7): with the lights, the segment's specular parameters and the
// voxel normal fixed, every observation B_k of a voxel gives one diffuse albedo by solving
// eq. (6) for kd, eq. (7):
//   kd = pi * (B_k - ks * sum_l exp(gamma_l) / N_l * L_l cos(theta_i,l)) / sum_l L_l cos(theta_i,l)
// and the voxel's kd is the mean over its observations (the paper) or, more robustly, their
// per-channel median. L_l = intensity_l / r_l^2 (near-field point lights). Unlike the paper,
// which ignores shadows and interreflections, the sums run over the lights that reach the voxel
// (its shadow rays, reflectance/light_transport.h), and the irradiance in the denominator adds
// the voxel's indirect irradiance E_ind gathered from the surfaces around it. With diffuse
// interreflection the image model is
//   B_k = kd / pi * (sum_l L_l cos(theta_i,l) + E_ind) + ks * sum_l exp(gamma_l) / N_l * ...
// plus the specular reflection of the indirect light, ks * L_k * rho(theta_o) with L_k the
// radiance observation k's lobe mirrors (LightTransportParams::indirect_specular: what its lobe
// ray met, PointLighting::mirrored, or an even sky, PointLighting::indirect_radiance; none when
// off), subtracted with the lights' specular terms. So kd is solved by dividing by the
// total irradiance rather than by subtracting kd_current / pi * E_ind from B_k: that needs no
// albedo estimate (which the subtraction would feed back on itself: a kd that is too bright
// takes too much out), and it still gives an albedo where every light is shadowed and only
// indirect light falls.
#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <optional>
#include <string>
#include <vector>

#include "reflectance/light_incidence.h"
#include "reflectance/observation.h"
#include "render/scene.h"

namespace glint::reflectance {

// How a voxel's per-observation albedos are combined. The median resists the observations
// whose specular term is mispredicted: near the mirror direction of a light a small error in
// the segment's alpha or ks changes the lobe, and so that observation's kd, a lot.
enum class AlbedoAverage { mean, median };
const char* albedo_average_name(AlbedoAverage average);       // "mean" | "median"
AlbedoAverage parse_albedo_average(const std::string& name);  // throws glint::Error

struct RefinedAlbedo {
  Eigen::Vector3f kd = Eigen::Vector3f::Zero();
  // Tangent of the light's effective incidence angle,
  // t = sum_l L_l sin(theta_i,l) / sum_l L_l cos(theta_i,l). Eq. (7) divides by the irradiance,
  // and a normal tilted by d changes that by about t d: under grazing light (cosine 0.2, t ~ 5)
  // a 2-degree tilt is a 17 % error in kd.
  float light_tangent = 0.0f;
  // The gathered indirect light's share of the irradiance eq. (7) divided by (by luminance).
  float indirect_share = 0.0f;
  // Every observation had clipped: kd is a lower bound on the albedo, not an estimate of it.
  bool lower_bound = false;
  // DiffuseObservation::radiance_error: eq. (7)'s albedo is off by as much, relatively.
  float radiance_error = 0.0f;
  float light_cosine() const { return 1.0f / std::sqrt(1.0f + light_tangent * light_tangent); }
};

// The weight of a voxel's refined albedo among its neighbours' (reflectance/material_maps.h):
// the inverse of its variance under a normal error d, (t d)^2, with t the light's effective
// incidence tangent, relative to light at 45 degrees or steeper (t <= 1, weight 1), where the
// normal no longer dominates the error. Eq. (7) under grazing light then counts less than its
// better-lit neighbours instead of the same: at cosine 0.3 a tenth.
inline float refined_albedo_weight(float light_tangent) {
  return 1.0f / std::max(1.0f, light_tangent * light_tangent);
}
// The tangent of the angle whose cosine is `cosine` in [0, 1] (infinite at 0).
inline float tangent_of(float cosine) { return std::sqrt(1 - cosine * cosine) / cosine; }

// Whether a voxel's refined albedo is within a factor max_ratio (>= 1) of its segment's
// reference albedo, both as their largest channel (a shadow dims every channel; a red patch on a
// grey segment keeps one bright): beyond it the light model does not explain the voxel's
// observations (ReflectanceParams::albedo_max_ratio). max_ratio 0, or no reference (NaN),
// accepts every albedo.
inline bool explained_by_light(float refined, float reference, float max_ratio) {
  if (max_ratio == 0 || std::isnan(reference)) return true;
  return refined * max_ratio >= reference && refined <= reference * max_ratio;
}

// What a voxel's refined albedo (its largest channel `refined`) is worth against its segment's
// reference: an estimate (usable where its light can be trusted), or none, and then the share of
// direct light it lacked, which re-renderings take away (0 where it lacked none).
struct AlbedoVerdict {
  bool estimate = true;
  float light_shortfall = 0.0f;
};
// A lower bound (RefinedAlbedo::lower_bound) below the reference says less than the reference
// does: no estimate, and no light lacking (it is dark for want of the sensor's range). Beyond
// max_ratio (explained_by_light()) no estimate either; if it is too dark, the light is short by
// 1 - refined / reference. max_ratio 0, or no reference (NaN), accepts every albedo.
inline AlbedoVerdict judge_albedo(float refined, bool lower_bound, float reference,
                                  float max_ratio) {
  if (max_ratio == 0 || std::isnan(reference)) return {};
  if (lower_bound && refined < reference) return {false, 0.0f};
  if (explained_by_light(refined, reference, max_ratio)) return {};
  return {false, std::max(0.0f, 1 - refined / reference)};
}

// A light shortfall re-judged by the albedo of the same observations with no specular term taken
// out (`without_lobe`, its largest channel): where that is not too dark, the observations hold
// the light, and the lobe, predicting more highlight than they show (a network's gloss on a matte
// wall), made the albedo dark: still no estimate, but no light lacking.
inline AlbedoVerdict judge_without_lobe(AlbedoVerdict verdict, float without_lobe, float reference,
                                        float max_ratio) {
  if (verdict.light_shortfall > 0 && without_lobe * max_ratio >= reference)
    verdict.light_shortfall = 0;
  return verdict;
}

// A voxel's observations reduced to the two sides of eq. (7): the diffuse radiance, each
// observation's radiance less its specular term, combined by an AlbedoAverage, and the
// irradiance it answers to. kd = pi * radiance / irradiance per channel (the average commutes
// with the division: the irradiance is the same for every observation of the voxel).
struct DiffuseObservation {
  Eigen::Vector3f radiance = Eigen::Vector3f::Zero();
  // sum_l L_l cos(theta_i,l) over the lights that reach the voxel, plus its indirect irradiance.
  Eigen::Vector3f irradiance = Eigen::Vector3f::Zero();
  // The same as luminance (mean over channels): all of it, the lights' with cos replaced by sin
  // (RefinedAlbedo::light_tangent), and the indirect part.
  float cosines = 0.0f, sines = 0.0f, indirect = 0.0f;
  bool lower_bound = false;  // every observation had clipped
  // The relative standard error of the combined radiance, from how the observations' diffuse
  // luminances scatter: 1.4826 MAD / median over sqrt(n), 0 below kMinScatterObservations.
  // A voxel straddling two faces or a misfit lobe scatters; a bias every observation shares
  // (a wrong normal under one light) does not, and albedo_error() adds it by the light's angle.
  // Eq. (7)'s albedo inherits the error (shrink_albedo()).
  float radiance_error = 0.0f;
};
inline constexpr int kMinScatterObservations = 3;

// The observations of a voxel under `lighting` (the lights that reach it, its indirect
// irradiance): those seen from above the surface, at most kMaxObservationsPerVoxel, combined by
// `average`; nullopt when there is none. Observations with a channel at `saturated_radiance` or
// above have clipped: their radiance is a lower bound, so they are left out unless all of them
// clipped. No allocation.
std::optional<DiffuseObservation> observe_diffuse(
    const Observation* observations, int count, const Eigen::Vector3f& position,
    const Eigen::Vector3f& normal, const std::vector<render::PointLight>& lights,
    const Eigen::Vector3f& ks, float alpha, AlbedoAverage average = AlbedoAverage::mean,
    float saturated_radiance = INFINITY, const PointLighting& lighting = {});

// Eq. (7) for `observed` with `unseen` more irradiance (per channel, counted as indirect light:
// reflectance/unseen_light.h); nullopt where no light reaches the surface point.
std::optional<RefinedAlbedo> solve_albedo(const DiffuseObservation& observed,
                                          const Eigen::Vector3f& unseen = Eigen::Vector3f::Zero());

// One sample of the gather's scene scale (LightTransportParams::indirect_scaled) from a voxel no
// light reaches directly (`observed.cosines` holds its indirect light alone): its diffuse radiance
// is kd / pi * E_true, so pi * radiance / gathered is kd * E_true / E_gathered, and over the
// segment's reference albedo (largest channels) the ratio E_true / E_gathered. NaN where it
// gives none: direct light, a lower bound, no reference, a channel not gathered.
float indirect_scale_sample(const DiffuseObservation& observed, const Eigen::Vector3f& gathered,
                            float reference);

// A voxel's relative albedo error, three parts taken as independent: its observations' scatter,
// the gathered light's error (its share of the irradiance times the gather's relative error
// `gather_error`), and its normal's, t * `normal_error` (radians; RefinedAlbedo::light_tangent),
// which every observation shares and so does not scatter.
inline float albedo_error(const RefinedAlbedo& refined, float gather_error, float normal_error) {
  return std::hypot(refined.radiance_error, refined.indirect_share * gather_error,
                    refined.light_tangent * normal_error);
}

// Empirical Bayes shrinkage of a voxel's refined albedo towards its segment's where its own error
// dominates it: kd * (reference / max kd)^(1 - w), w = spread^2 / (spread^2 + error^2), in the
// log of the brightness (largest channel), whose error is relative. `error`: the voxel's
// relative albedo error (albedo_error()); `spread`: its segment's own spread of log
// brightness (texture and noise) where that error is small; `reference`: the segment's
// brightness. The colour is kept. No error, no spread known (NaN) or no reference: kd as it is.
Eigen::Vector3f shrink_albedo(const Eigen::Vector3f& kd, float reference, float error,
                              float spread);

}  // namespace glint::reflectance
