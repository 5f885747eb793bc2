#include "reflectance/segment_map.h"

#include <algorithm>
#include <numeric>

#include "core/error.h"

namespace glint::reflectance {
namespace {

// How many visible voxels ahead update() asks for a voxel's segment id.
constexpr std::size_t kPrefetchDistance = 16;

}  // namespace

SegmentMap::SegmentMap(const SegmentMapParams& params) : params_(params), random_(params.seed) {
  if (params.reservoir_capacity < 1)
    throw Error("segment map", "reservoir_capacity", "must be >= 1");
}

SegmentMap::Reservoir& SegmentMap::reservoir(int segment) {
  if (segment >= int(segments_.size())) segments_.resize(segment + 1);
  return segments_[segment];
}

int SegmentMap::reservoir_size(int segment) const {
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
  Reservoir& members = reservoir(segment);
  ++members.joined;
  offer(members, voxel);
}

void SegmentMap::offer(Reservoir& members, int voxel) {
  // Vitter's algorithm R: after n offers each of them is in the buffer with probability
  // capacity / n.
  if (int(members.voxels.size()) < params_.reservoir_capacity) {
    members.voxels.push_back(voxel);
    return;
  }
  const std::uint64_t slot =
      std::uniform_int_distribution<std::uint64_t>(0, members.joined - 1)(random_);
  if (slot < members.voxels.size()) members.voxels[slot] = voxel;
}

int SegmentMap::resolve(int segment) const {
  while (segment < int(merged_into_.size()) && merged_into_[segment] > 0)
    segment = merged_into_[segment];
  return segment;
}

void SegmentMap::merge(ObservationGrid& grid, int kept, int gone) {
  for (int v = 0; v < int(grid.voxel_count()); ++v)
    if (grid.segment(v) == gone) grid.segment(v) = kept;
  Reservoir& from = reservoir(gone);
  Reservoir& into = reservoir(kept);
  // `from`'s entries join `into`'s stream as its next `from.joined` members, each standing for
  // an equal share of them (exact while `from` had not overflowed, approximate after).
  const std::uint64_t base = into.joined, entries = from.voxels.size();
  for (std::uint64_t k = 0; k < entries; ++k) {
    into.joined = base + from.joined * (k + 1) / entries;
    offer(into, from.voxels[k]);
  }
  from = Reservoir{};
  if (gone >= int(merged_into_.size())) merged_into_.resize(gone + 1, 0);
  merged_into_[gone] = kept;
  ++merges_;
}

void SegmentMap::update(ObservationGrid& grid, const std::vector<VisibleVoxel>& visible,
                        const Image<std::int32_t>& frame_labels, bool labels_are_global) {
  const std::int32_t* labels = frame_labels.plane(0);
  // One slot per distinct frame label the visible voxels carry (neighbouring voxels mostly
  // share one, so the hash is consulted only when the label changes).
  slot_of_label_.clear();
  slot_label_.clear();
  voxel_slot_.resize(visible.size());
  std::int32_t last_label = 0;  // labels are positive: no voxel matches it at first
  int last_slot = -1;
  for (std::size_t k = 0; k < visible.size(); ++k) {
    const std::int32_t label = labels[visible[k].pixel];
    if (label <= 0) {
      voxel_slot_[k] = -1;
      continue;
    }
    if (label != last_label) {
      const auto [found, added] = slot_of_label_.try_emplace(label, int(slot_label_.size()));
      if (added) slot_label_.push_back(label);
      last_label = label;
      last_slot = found->second;
    }
    voxel_slot_[k] = last_slot;
  }
  const std::size_t slots = slot_label_.size();
  slot_segment_.assign(slots, 0);  // 0 = the label gets no global id this frame
  if (labels_are_global) {
    for (std::size_t slot = 0; slot < slots; ++slot) slot_segment_[slot] = slot_label_[slot];
  } else {
    // Overlap of every frame label with the global ids its voxels carry (0 = none yet).
    if (slot_overlap_.size() < slots) slot_overlap_.resize(slots);
    for (std::size_t slot = 0; slot < slots; ++slot) slot_overlap_[slot].clear();
    for (std::size_t k = 0; k < visible.size(); ++k) {
      if (k + kPrefetchDistance < visible.size())
        grid.prefetch_segment(visible[k + kPrefetchDistance].voxel);
      if (voxel_slot_[k] < 0) continue;
      std::vector<std::pair<int, int>>& overlap = slot_overlap_[voxel_slot_[k]];
      const int id = grid.segment(visible[k].voxel);
      const auto entry = std::find_if(overlap.begin(), overlap.end(),
                                      [id](const std::pair<int, int>& e) { return e.first == id; });
      if (entry != overlap.end())
        ++entry->second;
      else
        overlap.emplace_back(id, 1);
    }
    // Labels in ascending order: new global ids are handed out in that order.
    slot_order_.resize(slots);
    std::iota(slot_order_.begin(), slot_order_.end(), 0);
    std::sort(slot_order_.begin(), slot_order_.end(),
              [&](int a, int b) { return slot_label_[a] < slot_label_[b]; });
    for (const int slot : slot_order_) {
      // Ids merged earlier in this frame count as the segment they went into; ascending ids.
      std::vector<std::pair<int, int>>& counts = slot_overlap_[slot];
      for (auto& [id, count] : counts) id = id > 0 ? resolve(id) : 0;
      std::sort(counts.begin(), counts.end());
      std::size_t distinct = 0;
      for (const auto& entry : counts)
        if (distinct > 0 && counts[distinct - 1].first == entry.first)
          counts[distinct - 1].second += entry.second;
        else
          counts[distinct++] = entry;
      counts.resize(distinct);
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
      if (best_id > 0 && best_count >= params_.min_overlap * total) {
        slot_segment_[slot] = best_id;
      } else if (total >= params_.min_new_segment_voxels) {
        slot_segment_[slot] = int(segments_.size());  // a new segment
        segments_.emplace_back();
      }
    }
  }
  frame_segments_.clear();
  for (std::size_t slot = 0; slot < slots; ++slot)
    if (slot_segment_[slot] > 0) {
      slot_segment_[slot] = resolve(slot_segment_[slot]);
      frame_segments_.push_back(slot_segment_[slot]);
    }
  for (std::size_t k = 0; k < visible.size(); ++k) {
    if (k + kPrefetchDistance < visible.size())
      grid.prefetch_segment(visible[k + kPrefetchDistance].voxel);
    if (voxel_slot_[k] >= 0 && slot_segment_[voxel_slot_[k]] > 0)
      assign(grid, visible[k].voxel, slot_segment_[voxel_slot_[k]]);
  }
  std::sort(frame_segments_.begin(), frame_segments_.end());
  frame_segments_.erase(std::unique(frame_segments_.begin(), frame_segments_.end()),
                        frame_segments_.end());
}

int SegmentMap::sample(const ObservationGrid& grid, int segment, int count, int min_observations,
                       std::mt19937_64& random, int* voxels) const {
  if (segment <= 0 || segment >= int(segments_.size())) return 0;
  const std::vector<int>& members = segments_[segment].voxels;
  if (members.empty()) return 0;
  // One pass over the reservoir in a random order (a random start and a step coprime to its size):
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
