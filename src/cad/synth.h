#pragma once
// CAD-kernel training and evaluation clouds: random parts (cad/part.h) sampled and labelled
// from their B-rep (cad/sample.h) with randomised tessellations, samplings, densities, noise and
// outliers. Cloud `index` of a seed is always the same cloud.
#include <cstdint>
#include <vector>

#include "cad/part.h"
#include "cad/sample.h"
#include "edges/synth.h"

namespace glint::cad {

struct CadSynthParams {
  PartParams part;  // part.seed is the stream's seed
  std::vector<Sampling> samplings{Sampling::vertices, Sampling::uniform, Sampling::scan};
  int min_points = 4000;  // uniform and scan: log-uniform in the range; vertices: at most max
  int max_points = 40000;
  std::vector<double> noise_levels{0.0, 0.0, 0.25, 0.5, 1.0};  // sigma / spacing, one drawn
  double outlier_probability = 0.1;  // share of clouds with 1-5 % outliers
  int max_viewpoints = 3;            // scan: 1..max scanner positions
  double band = 0.3;                 // as SampleParams
  double boundary_band = 0.6;
  double sharp_angle_deg = 25.0;
};

// Throws glint::Error("cad synth parameters", key, reason).
void check_cad_synth_params(const CadSynthParams& params);

// Cloud `index`: positions normalised to a unit bounding-box diagonal; description holds the
// part's recipe (seed, index, operations), the sampling's parameters and seed, and "shape"
// ("cad-<recipe>-<sampling>", used in file names). A part the kernel cannot sample is redrawn
// (up to 4 times, recorded as "attempts"); throws glint::Error only when every draw failed.
edges::SynthCloud synthesize_cad_cloud(const CadSynthParams& params, std::uint64_t index);

}  // namespace glint::cad
