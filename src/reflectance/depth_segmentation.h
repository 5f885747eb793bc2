#pragma once
// Per-frame geometric segmentation of a depth image after Tateno, Tombari and Navab (ICRA
// 2016), as paper 1 §3.5 uses it: objects are assumed mostly convex, so segments are the
// connected regions between concave boundaries and depth discontinuities.
//   vertex map V and normals N (central differences, facing the camera)
//   concavity  phi_c(u) = min_i [1 if (v_i - v).n <= eps else n.n_i]   edge if phi_c < tau_c
//              (eps grows with the sensor noise sigma(z), see DepthSegmentationParams)
//   distance   phi_d(u) = max_i |(v_i - v).n|                          edge if phi_d > k sigma(z)
//   plus a depth-discontinuity test |z_i - z| / z > ratio
// with sigma(z) = 0.0012 + 0.0019 (z - 0.4)^2 m, Kinect's axial noise (Nguyen et al. 2012).
// Non-edge pixels form 4-connected components; small ones are dropped; edge pixels then take
// the label of the nearest labelled pixel within a small window.
#include <cstdint>
#include <vector>

#include "core/camera.h"
#include "core/image.h"

namespace glint::reflectance {

struct DepthSegmentationParams {
  int normal_step_px = 2;     // central-difference offset for normals
  int neighbour_step_px = 2;  // the 8 neighbours v_i sit this many pixels away
  // eps = max(convexity_epsilon_m, convexity_noise_k sigma(z)): neighbours this far in front of
  // the tangent plane still count convex. Within the sensor's noise the side a neighbour lies on
  // is noise, and n.n_i of noisy normals often falls below tau_c. On 7-Scenes' kitchen (Kinect
  // v1; means over its 50 frames) a fixed 0.5 mm marked 62 % of the valid pixels as edges and
  // left 59 % unlabelled; 0.5 sigma(z): 51 % and 27 %. A concave corner's neighbours lie
  // centimetres in front (neighbour_step_px apart), well beyond it.
  float convexity_epsilon_m = 0.0005f;
  float convexity_noise_k = 0.5f;
  float min_convexity = 0.94f;        // tau_c
  float distance_k = 6.0f;            // k in k sigma(z)
  float discontinuity_ratio = 0.05f;  // |dz| / z
  int min_segment_px = 300;           // smaller components become unlabelled (0)
  int fill_radius_px = 4;             // edge pixels take a label from this window
};

struct DepthSegmentation {
  Image<std::int32_t> labels;  // 0 = no segment (invalid depth, edge not filled, too small)
  int segment_count = 0;       // labels are 1..segment_count
  Image<std::uint8_t> edges;   // 1 where a concave boundary or discontinuity was detected
};

// Segments a stream of depth images. It keeps its buffers between frames, so frames of one
// size allocate nothing after the first (fresh pages cost as much as the work at 256x212).
class DepthSegmenter {
 public:
  explicit DepthSegmenter(const DepthSegmentationParams& params = {});

  // depth: 1 channel, metres along the optical axis, 0 or non-finite = no measurement. The
  // result stays valid until the next call.
  const DepthSegmentation& segment(const ImageF& depth, const Intrinsics& intrinsics);

 private:
  // A horizontal run of non-edge pixels [begin, end) of one row, a node of the union-find.
  struct Run {
    int row, begin, end;
  };
  struct Offset {
    int dx, dy;
  };
  void compute_vertices_and_normals(const ImageF& depth, const Intrinsics& intrinsics);
  void detect_edges();
  void label_components();
  void fill_edges();
  int find_root(int run);

  DepthSegmentationParams params_;
  int width_ = 0, height_ = 0;
  // Vertex and normal maps as planes (x, y, z); no depth: vertex z = 0; no normal: all 0.
  std::vector<float> vertex_[3], normal_[3];
  std::vector<Offset> fill_window_;  // the edge fill's search order
  std::vector<Run> runs_;
  std::vector<int> run_parent_, component_size_, label_of_root_;
  std::vector<std::int32_t> component_;  // labels before the edge fill
  DepthSegmentation result_;
};

// One image; see DepthSegmenter.
DepthSegmentation segment_depth(const ImageF& depth, const Intrinsics& intrinsics,
                                const DepthSegmentationParams& params = {});

}  // namespace glint::reflectance
