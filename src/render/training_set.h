#pragma once
// The HemiCNN training set, glint's replacement for SynBRDF (paper 1 §4.1; Kim et al. 2017):
// many short RGB-D sequences, each of one object with one random homogeneous Ward material,
// lit by random near-field point lights and, sometimes, an environment map, seen by a camera
// moving along a short arc. Everything is drawn from (seed, sequence index) alone, so a set is
// reproducible, can be extended, and an interrupted run resumes where it stopped.
//
// Ranges (Pellacini et al. 2000):
//   kd      per channel 0.05-0.9: CIELAB colour drawn uniformly (L 25-96, a and b +-80) and kept
//           when its linear RGB falls in range (perceptually even hues and lightness);
//   ks      from the gloss contrast c ~ U(0, 0.2): ks_i = (c + cbrt(kd_i/2))^3 - kd_i/2, with c
//           capped per channel so that kd_i + ks_i <= 1 (bright albedos get less gloss);
//   alpha   log-uniform 0.02 (very glossy) - 0.35 (rough);
//   shapes  sphere, box (random proportions), Stanford bunny, spot, teapot, suzanne, cow,
//           fandisk, homer, rocker-arm (DATA/meshes), 0.3-0.8 m high, random yaw;
//   lights  1-3 point lights on a shell 1-3 m around the object's centre (and at least 0.3 m
//           outside its bounding sphere), 10-80 deg above the horizon, within +-110 deg in
//           azimuth of the camera's mean direction, each giving an irradiance of 1.5-4 at the
//           centre, each channel scaled by 0.85-1 (tint);
//   environment with probability environment_probability: one of DATA/envmaps/*.hdr, random
//           rotation, scale 0.1-0.4, 32 samples per pixel;
//   camera  an arc of 40-120 deg around the object at elevation 5-45 deg, the object's
//           bounding sphere filling 60-90 % of the image height.
#include <Eigen/Core>
#include <cstdint>
#include <functional>
#include <nlohmann/json_fwd.hpp>
#include <string>
#include <vector>

#include "render/scene.h"

namespace glint::render {

struct MaterialRanges {
  float kd_min = 0.05f, kd_max = 0.9f;  // per channel, linear
  float c_max = 0.2f;                   // Pellacini gloss contrast, drawn from [0, c_max]
  float alpha_min = 0.02f, alpha_max = 0.35f;
  // Share of albedos drawn with CIELAB chroma uniform in radius (hue uniform) instead of a, b
  // uniform in a square. Of the draws inside [kd_min, kd_max], the square puts about 1 in 77
  // within chroma 5 of the grey axis, the radius about 1 in 7. 0 draws no extra number, so sets
  // made before this option reproduce.
  float near_grey_share = 0;
};

struct TrainingSetParams {
  int sequences = 1000;  // 13-15 min and ~2.1 GB on 2 cores (docs/benchmarks.md)
  int frames = 30;       // per sequence
  int width = 160, height = 132;
  std::uint64_t seed = 1;
  std::string data_dir;  // holds meshes/ and envmaps/
  // Shape names drawn from (training_shape_names()); empty = all.
  std::vector<std::string> shapes;
  double environment_probability = 0.3;
  bool ground_truth = true;  // write gt/ (the targets need gt/kd, gt/ks, gt/alpha)
  MaterialRanges ranges;
};

// "sphere", "box" and the mesh names ("bunny", "spot", ...).
const std::vector<std::string>& training_shape_names();

// A generator of uniform numbers from a 64-bit seed, the same on every platform.
class SeededDraw {
 public:
  explicit SeededDraw(std::uint64_t seed) : state_(seed) {}
  double uniform();                         // [0, 1)
  double uniform(double low, double high);  // [low, high)
  int integer(int low, int high);           // [low, high]
  double log_uniform(double low, double high);

 private:
  std::uint64_t state_;
};

// One random material inside `ranges` (see the header comment).
WardMaterial sample_training_material(const MaterialRanges& ranges, SeededDraw& draw);

// Sequence `index` of the set: the scene (object id 1, lights, environment, camera arc).
// Throws glint::Error for an unknown shape name, or when an environment is requested and
// DATA/envmaps holds no .hdr file.
Scene make_training_scene(const TrainingSetParams& params, int index);

struct TrainingSetStats {
  int rendered = 0;  // sequences rendered by this run
  int skipped = 0;   // already complete from an earlier run
  double seconds = 0;
};

// Writes OUT/seq_00000 ... (render/sequence_writer.h format) and OUT/index.json (parameters,
// ranges, and per sequence: folder, shape, material, lights, environment). Complete sequence
// folders are skipped, so re-running the same command resumes; an OUT/index.json made with
// other parameters is an error (glint::Error), to keep one set consistent.
// `on_sequence` (optional) is called after each sequence, rendered or skipped (the sequences
// show no progress bars of their own; a caller can show one over the set with it).
TrainingSetStats write_training_set(const TrainingSetParams& params, const std::string& out_dir,
                                    const std::function<void()>& on_sequence = {});

// The index.json description of params (what must match for a resume).
nlohmann::json training_set_parameters_json(const TrainingSetParams& params);

}  // namespace glint::render
