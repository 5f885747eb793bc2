#include "cad/synth.h"

#include <cmath>
#include <random>

#include "core/error.h"
#include "core/hash.h"

namespace glint::cad {
namespace {

using Rng = std::mt19937_64;

double uniform(Rng& rng, double low, double high) {
  return std::uniform_real_distribution<double>(low, high)(rng);
}

// The sampling of cloud `index`, from a stream of its own (independent of the part's draws).
SampleParams random_sampling(const CadSynthParams& params, std::uint64_t index) {
  Rng rng(mix64(params.part.seed ^ mix64(index ^ 0x73616d70ULL)));
  SampleParams s;
  s.sampling = params.samplings[std::uniform_int_distribution<std::size_t>(
      0, params.samplings.size() - 1)(rng)];
  s.points = static_cast<int>(std::lround(
      std::exp(uniform(rng, std::log(params.min_points), std::log(params.max_points)))));
  if (s.sampling == Sampling::vertices) {
    // Deflections a CAD exporter might use; planes' triangles split down to 1-5 % of the
    // diagonal, so planes are several times sparser than curved faces but not empty.
    s.points = params.max_points;
    s.linear_deflection = std::exp(uniform(rng, std::log(2e-4), std::log(2e-3)));
    s.angular_deflection_deg = uniform(rng, 6.0, 25.0);
    s.plane_edge_fraction = std::exp(uniform(rng, std::log(0.01), std::log(0.05)));
  }
  s.viewpoints = params.max_viewpoints;
  s.noise = params.noise_levels[std::uniform_int_distribution<std::size_t>(
      0, params.noise_levels.size() - 1)(rng)];
  s.outlier_share =
      uniform(rng, 0.0, 1.0) < params.outlier_probability ? uniform(rng, 0.01, 0.05) : 0.0;
  s.band = params.band;
  s.boundary_band = params.boundary_band;
  s.sharp_angle_deg = params.sharp_angle_deg;
  s.normalise = true;
  s.seed = rng();
  return s;
}

}  // namespace

void check_cad_synth_params(const CadSynthParams& p) {
  const std::string where = "cad synth parameters";
  check_part_params(p.part);
  if (p.samplings.empty()) throw Error(where, "sampling", "give at least one sampling");
  if (p.min_points < 200 || p.max_points < p.min_points)
    throw Error(where, "points", "need 200 <= min <= max");
  if (p.noise_levels.empty()) throw Error(where, "noise", "give at least one noise level");
  if (!(p.outlier_probability >= 0.0 && p.outlier_probability <= 1.0))
    throw Error(where, "outliers", "must be in [0, 1]");
  SampleParams check;
  check.band = p.band;
  check.boundary_band = p.boundary_band;
  check.sharp_angle_deg = p.sharp_angle_deg;
  check.viewpoints = p.max_viewpoints;
  for (double level : p.noise_levels) {
    check.noise = level;
    check_sample_params(check);
  }
}

edges::SynthCloud synthesize_cad_cloud(const CadSynthParams& params, std::uint64_t index) {
  check_cad_synth_params(params);
  const SampleParams sampling = random_sampling(params, index);
  nlohmann::json failures = nlohmann::json::array();
  constexpr int kAttempts = 4;
  for (int attempt = 0; attempt < kAttempts; ++attempt) {
    PartParams part_params = params.part;
    if (attempt > 0) part_params.seed = mix64(params.part.seed + attempt);
    const Part part = random_part(part_params, index);
    try {
      LabelledCloud labelled = sample_shape(part.shape, sampling);
      edges::SynthCloud cloud;
      cloud.cloud = std::move(labelled.cloud);
      cloud.description = std::move(labelled.description);
      cloud.description["index"] = index;
      cloud.description["shape"] = "cad-" + part.recipe["recipe"].get<std::string>() + "-" +
                                   cloud.description["sampling"].get<std::string>();
      cloud.description["part"] = part.recipe;
      cloud.description["sampling_seed"] = sampling.seed;
      cloud.description["attempts"] = attempt + 1;
      if (!failures.empty()) cloud.description["failed_attempts"] = failures;
      return cloud;
    } catch (const Error& e) {
      failures.push_back(e.what());
    }
  }
  throw Error("cad synth", std::to_string(index),
              "every part draw failed: " + failures.back().get<std::string>());
}

}  // namespace glint::cad
