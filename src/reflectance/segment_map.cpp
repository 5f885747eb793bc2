#include "reflectance/segment_map.h"

#include <algorithm>
#include <map>
#include <numeric>

namespace glint::reflectance {

SegmentMap::Ring& SegmentMap::ring(int segment) {
  if (segment >= int(segments_.size())) segments_.resize(segment + 1);
  return segments_[segment];
}

int SegmentMap::ring_size(int segment) const {
  return segment > 0 && segment < int(segments_.size()) ? int(segments_[segment].voxels.size()) : 0;
}

void SegmentMap::assign(ObservationGrid& grid, int voxel, int segment) {
  std::int32_t& current = grid.segment(voxel);
  std::int16_t& confidence = grid.segment_confidence(voxel);
  if (current == segment) {
    confidence = std::int16_t(std::min<int>(confidence + 1, params_.max_confidence));
    return;
  }
  if (current != 0 && --confidence > 0) return;
  current = segment;
  confidence = 1;
  Ring& members = ring(segment);
  if (int(members.voxels.size()) < params_.ring_capacity) {
    members.voxels.push_back(voxel);
  } else {
    members.voxels[members.next] = voxel;
    members.next = (members.next + 1) % members.voxels.size();
  }
}

int SegmentMap::resolve(int segment) const {
  while (segment < int(merged_into_.size()) && merged_into_[segment] > 0)
    segment = merged_into_[segment];
  return segment;
}

void SegmentMap::merge(ObservationGrid& grid, int kept, int gone) {
  for (int v = 0; v < int(grid.voxel_count()); ++v)
    if (grid.segment(v) == gone) grid.segment(v) = kept;
  Ring& from = ring(gone);
  Ring& into = ring(kept);
  for (int voxel : from.voxels) {
    if (int(into.voxels.size()) >= params_.ring_capacity) break;
    into.voxels.push_back(voxel);
  }
  from = Ring{};
  if (gone >= int(merged_into_.size())) merged_into_.resize(gone + 1, 0);
  merged_into_[gone] = kept;
  ++merges_;
}

void SegmentMap::update(ObservationGrid& grid, const std::vector<VisibleVoxel>& visible,
                        const Image<std::int32_t>& frame_labels, bool labels_are_global) {
  const std::int32_t* labels = frame_labels.plane(0);
  std::map<int, int> global_of_label;
  if (labels_are_global) {
    for (const VisibleVoxel& seen : visible)
      if (labels[seen.pixel] > 0) global_of_label[labels[seen.pixel]] = labels[seen.pixel];
  } else {
    // Overlap of every frame label with the global ids its voxels carry (0 = none yet).
    std::map<int, std::map<int, int>> overlap;
    for (const VisibleVoxel& seen : visible)
      if (labels[seen.pixel] > 0) ++overlap[labels[seen.pixel]][grid.segment(seen.voxel)];
    for (const auto& [label, raw_counts] : overlap) {
      // Ids merged earlier in this frame count as the segment they went into.
      std::map<int, int> counts;
      for (const auto& [id, count] : raw_counts) counts[id > 0 ? resolve(id) : 0] += count;
      int total = 0, best_id = 0, best_count = 0;
      for (const auto& [id, count] : counts) {
        total += count;
        if (id > 0 && count > best_count) best_id = id, best_count = count;
      }
      for (const auto& [id, count] : counts)
        if (id > 0 && id != best_id && count >= params_.merge_fraction * total &&
            best_count >= params_.merge_fraction * total) {
          merge(grid, best_id, id);  // one surface in this frame, two segments so far
          best_count += count;
        }
      if (best_id > 0 && best_count >= params_.min_overlap * total)
        global_of_label[label] = best_id;
      else if (total >= params_.min_new_segment_voxels) {
        global_of_label[label] = int(segments_.size());  // a new segment
        segments_.emplace_back();
      }
    }
  }
  frame_segments_.clear();
  for (const VisibleVoxel& seen : visible) {
    const int label = labels[seen.pixel];
    if (label <= 0) continue;
    const auto found = global_of_label.find(label);
    if (found != global_of_label.end()) assign(grid, seen.voxel, resolve(found->second));
  }
  for (const auto& [label, id] : global_of_label) frame_segments_.push_back(resolve(id));
  std::sort(frame_segments_.begin(), frame_segments_.end());
  frame_segments_.erase(std::unique(frame_segments_.begin(), frame_segments_.end()),
                        frame_segments_.end());
}

int SegmentMap::sample(const ObservationGrid& grid, int segment, int count, int min_observations,
                       std::mt19937_64& random, int* voxels) const {
  if (segment <= 0 || segment >= int(segments_.size())) return 0;
  const std::vector<int>& members = segments_[segment].voxels;
  if (members.empty()) return 0;
  // One pass over the ring in a random order (a random start and a step coprime to its size):
  // every member is looked at once, so rarely observed voxels cannot starve the sample.
  const std::size_t n = members.size();
  std::uniform_int_distribution<std::size_t> pick(0, n - 1);
  const std::size_t start = pick(random);
  std::size_t step = n > 1 ? 1 + pick(random) % (n - 1) : 1;
  while (std::gcd(step, n) != 1) ++step;
  int found = 0;
  for (std::size_t k = 0; k < n && found < count; ++k) {
    const int v = members[(start + k * step) % n];
    if (grid.segment(v) != segment || grid.observation_count(v) < min_observations ||
        std::find(voxels, voxels + found, v) != voxels + found)
      continue;
    voxels[found++] = v;
  }
  return found;
}

}  // namespace glint::reflectance
