#pragma once
// Globally consistent segments over time (paper 1 §3.5; Tateno et al. 2016 §4): each frame's
// depth segmentation (reflectance/depth_segmentation.h) labels the observation voxels it sees,
// and those per-frame labels are propagated into global segment ids.
//  - A frame segment takes the global id that most of its already-labelled voxels carry, when
//    they are at least min_overlap of its voxels; otherwise, if it has min_new_segment_voxels
//    voxels, it starts a new global segment.
//  - When one frame segment covers two global segments, each with at least merge_fraction of
//    its voxels, they are one surface seen in pieces before: the one covering fewer of them is
//    merged into the other (its voxels relabelled, its reservoir offered to the other).
//  - A voxel's id changes only after repeated disagreement: agreeing frames raise its
//    confidence (up to max_confidence), disagreeing ones lower it, and at 0 it switches.
// Each global segment owns a fixed-size reservoir of voxel references (the paper's ring buffer),
// from which the specular estimation samples its voxels. It is kept a uniform random sample of
// every voxel that joined the segment (reservoir sampling): overwriting the oldest entry, as a
// ring would, left it holding only the newest members whenever a segment grew by more than
// its capacity per frame (cubes' floor at 1 cm: 4,000-8,000 new voxels per frame), whose
// single observations no sample can use. Entries may be stale (the voxel changed segment):
// samplers check.
// In ground-truth mode the frame labels are already global ids (the synthetic gt/segment
// images) and are written to the voxels directly.
#include <cstdint>
#include <random>
#include <unordered_map>
#include <utility>
#include <vector>

#include "core/image.h"
#include "reflectance/observation_grid.h"

namespace glint::reflectance {

struct SegmentMapParams {
  int reservoir_capacity = 4096;  // voxel references per segment
  std::uint64_t seed = 1;         // of the reservoirs' sampling
  double min_overlap = 0.3;
  int min_new_segment_voxels = 20;
  int max_confidence = 8;
  double merge_fraction = 0.4;  // > 0.5 never merges
};

class SegmentMap {
 public:
  explicit SegmentMap(const SegmentMapParams& params = {});

  // Labels the voxels observed in this frame. frame_labels: one value per pixel (0 = none);
  // labels_are_global: ground-truth ids instead of per-frame labels.
  void update(ObservationGrid& grid, const std::vector<VisibleVoxel>& visible,
              const Image<std::int32_t>& frame_labels, bool labels_are_global);

  // Global ids (> 0) that voxels of the latest frame carry, ascending.
  const std::vector<int>& frame_segments() const { return frame_segments_; }
  // Largest global id handed out so far.
  int max_segment_id() const { return int(segments_.size()) - 1; }
  // The segment a (possibly merged) id lives on as.
  int resolve(int segment) const;
  int merges() const { return merges_; }
  // Voxel references currently in the segment's reservoir (stale ones included).
  int reservoir_size(int segment) const;

  // Writes up to `count` distinct voxels of `segment` that still carry its id and have at
  // least `min_observations` observations, drawn at random from its reservoir (each member is
  // considered at most once, so at most reservoir_capacity checks); returns how many.
  int sample(const ObservationGrid& grid, int segment, int count, int min_observations,
             std::mt19937_64& random, int* voxels) const;

 private:
  struct Reservoir {
    std::vector<int> voxels;
    std::uint64_t joined = 0;  // voxels that ever joined the segment (the reservoir's stream)
  };
  Reservoir& reservoir(int segment);
  // Offers `voxel`, the `joined`-th member, to the reservoir: kept with probability
  // capacity / joined, in place of a random entry.
  void offer(Reservoir& members, int voxel);
  void assign(ObservationGrid& grid, int voxel, int segment);
  void merge(ObservationGrid& grid, int kept, int gone);

  SegmentMapParams params_;
  std::mt19937_64 random_;
  std::vector<Reservoir> segments_{1};  // index = global id; 0 unused
  std::vector<int> frame_segments_;
  std::vector<int> merged_into_;  // by id: the id it was merged into, 0 = none
  int merges_ = 0;
  // Scratch of update(), kept between frames: a slot per distinct frame label.
  std::unordered_map<int, int> slot_of_label_;
  std::vector<int> slot_label_, slot_segment_, slot_order_;
  std::vector<int> voxel_slot_;                                 // per visible voxel, -1 = none
  std::vector<std::vector<std::pair<int, int>>> slot_overlap_;  // (global id, voxels)
};

}  // namespace glint::reflectance
