#pragma once
// Reflectance observations (paper 1 §3.4): per voxel of the coarse observation grid, pairs of a
// linear RGB colour and the unit voxel-to-camera direction it was seen from, at most
// `capacity` (m = 30) of them. When a new observation overflows the voxel, one of the two most
// similar (closest in direction) is dropped, so the kept set tends towards uniform coverage
// of the hemisphere around the normal.
#include <Eigen/Core>
#include <array>
#include <bit>
#include <cstdint>
#include <vector>

namespace glint::reflectance {

// IEEE binary16 bits of a non-negative value (round to nearest; negative and NaN give 0, values
// above 65504 give 65504) and back. Exposed for the tests.
std::uint16_t half_from_float(float value);
inline float float_from_half(std::uint16_t half) {
  // The half's exponent and mantissa in a float's low exponent bits, rescaled by 2^(127 - 15):
  // exact for normal, subnormal and zero halves alike, and one multiply (the albedo stage decodes
  // 90 colours per voxel).
  return std::bit_cast<float>(std::uint32_t(half & 0x7fff) << 13) * 0x1p112f;
}

// One stored observation in 16 bytes instead of 28 as floats: the pools hold m = 30 per voxel,
// and at 1 cm their pages' first touch and their cache misses are a large part of the
// observation stage (cubes, 1 cm: 195 MB less peak memory). The colour is kept as IEEE binary16,
// relative error at most 2^-11 (an 8-bit input's step is 2^-8 or more); the direction as three
// signed 16-bit fractions, error at most 1.6e-5 per component.
class Observation {
 public:
  Observation() = default;  // black, along +z, frame 0
  // `colour`: linear RGB radiance; negative and NaN channels store 0, those above 65504 (the
  // largest half) store 65504. `direction`: a unit vector.
  Observation(const Eigen::Vector3f& colour, const Eigen::Vector3f& direction, std::uint32_t frame);

  Eigen::Vector3f colour() const {
    return {float_from_half(colour_[0]), float_from_half(colour_[1]), float_from_half(colour_[2])};
  }
  Eigen::Vector3f direction() const {  // unit to within the storage error
    return Eigen::Vector3f(direction_[0], direction_[1], direction_[2]) * (1.0f / kUnit);
  }
  std::uint32_t frame() const { return frame_; }  // the frame it was observed in
  // direction() . other.direction(), from the stored integers (the same on every call).
  float similarity(const Observation& other) const {
    const std::int32_t dot = std::int32_t(direction_[0]) * other.direction_[0] +
                             std::int32_t(direction_[1]) * other.direction_[1] +
                             std::int32_t(direction_[2]) * other.direction_[2];
    return float(dot) * (1.0f / (float(kUnit) * float(kUnit)));
  }

 private:
  friend struct ObservationLanes;  // the vectorised similarities (observation.cpp)
  static constexpr std::int16_t kUnit = 32767;
  std::array<std::uint16_t, 3> colour_{};  // binary16 bits
  std::array<std::int16_t, 3> direction_{0, 0, kUnit};
  std::uint32_t frame_ = 0;
};
static_assert(sizeof(Observation) == 16);

// For each stored observation, its most similar other stored observation: their direction dot
// product (-2 while it is alone) and its slot, one entry per slot in each of two arrays. Kept up
// to date by insert_observation, so the most similar pair of a full voxel is found in
// O(capacity) instead of O(capacity^2). Apart, a voxel's similarities are searched where they
// lie, and they and the slots take 5 bytes per observation instead of a padded 8 (at 1 cm the
// insertions' reads are mostly cache misses).
struct NearestObservations {
  float* similarity;
  std::uint8_t* slot;
};

// The most observations a voxel can hold: NearestObservations stores slots as bytes.
inline constexpr int kMaxObservationsPerVoxel = 255;

// Adds `added` to the `count` observations in slots[0, capacity) (capacity <=
// kMaxObservationsPerVoxel) and returns the new count; `nearest` holds one entry per slot. When
// the voxel is full, of the most similar pair (largest direction dot product over all pairs
// including the new one) the older observation is dropped: newer ones were taken with
// better-converged geometry. O(capacity) plus O(capacity) for each stored observation whose
// nearest one was dropped; no allocation.
int insert_observation(Observation* slots, NearestObservations nearest, int count, int capacity,
                       const Observation& added);

// The instruction sets insert_observation() has a kernel for; all give the same result bit for
// bit, and it runs the widest the CPU has.
enum class InsertionKernel { kScalar, kAvx2, kAvx512 };
// Those this CPU can run, narrowest first.
std::vector<InsertionKernel> supported_insertion_kernels();
// insert_observation() with one of supported_insertion_kernels() (tests compare each).
int insert_observation(InsertionKernel kernel, Observation* slots, NearestObservations nearest,
                       int count, int capacity, const Observation& added);

}  // namespace glint::reflectance
