#pragma once
// Reflectance observations (paper 1 §3.4): per voxel of the coarse observation grid, pairs of a
// linear RGB colour and the unit voxel-to-camera direction it was seen from, at most
// `capacity` (m = 30) of them. When a new observation overflows the voxel, one of the two most
// similar (closest in direction) is dropped, so the kept set tends towards uniform coverage
// of the hemisphere around the normal.
#include <Eigen/Core>
#include <cstdint>

namespace glint::reflectance {

struct Observation {
  Eigen::Vector3f colour = Eigen::Vector3f::Zero();      // linear RGB
  Eigen::Vector3f direction = Eigen::Vector3f::UnitZ();  // unit, surface towards camera, world
  std::uint32_t frame = 0;                               // frame it was observed in
};

// For each stored observation, its most similar other stored observation: the slot and their
// direction dot product (-2 while it is alone). Kept up to date by insert_observation, so the
// most similar pair of a full voxel is found in O(capacity) instead of O(capacity^2).
struct NearestObservation {
  float similarity = -2.0f;
  std::uint8_t slot = 0;
};

// The most observations a voxel can hold: NearestObservation stores slots as bytes.
inline constexpr int kMaxObservationsPerVoxel = 255;

// Adds `added` to the `count` observations in slots[0, capacity) (capacity <=
// kMaxObservationsPerVoxel) and returns the new count; `nearest` holds one entry per slot. When
// the voxel is full, of the most similar pair (largest direction dot product over all pairs
// including the new one) the older observation is dropped: newer ones were taken with
// better-converged geometry. O(capacity) plus O(capacity) for each stored observation whose
// nearest one was dropped; no allocation.
int insert_observation(Observation* slots, NearestObservation* nearest, int count, int capacity,
                       const Observation& added);

}  // namespace glint::reflectance
