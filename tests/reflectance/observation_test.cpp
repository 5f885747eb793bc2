#include "reflectance/observation.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

namespace glint::reflectance {
namespace {

Observation seen_from(float theta, float phi, std::uint32_t frame) {
  return Observation(
      Eigen::Vector3f::Constant(float(frame)),
      {std::sin(theta) * std::cos(phi), std::sin(theta) * std::sin(phi), std::cos(theta)}, frame);
}

// A voxel's slots with their nearest-neighbour bookkeeping.
struct Voxel {
  explicit Voxel(int capacity)
      : slots(capacity), similarity(capacity), nearest(capacity), capacity(capacity) {}
  void insert(const Observation& o) {
    count =
        insert_observation(slots.data(), {similarity.data(), nearest.data()}, count, capacity, o);
  }
  void insert(InsertionKernel kernel, const Observation& o) {
    count = insert_observation(kernel, slots.data(), {similarity.data(), nearest.data()}, count,
                               capacity, o);
  }
  std::vector<Observation> slots;
  std::vector<float> similarity;      // of each slot's nearest
  std::vector<std::uint8_t> nearest;  // its slot
  int capacity, count = 0;
};

// The definition, by brute force over all pairs including the new one (O(capacity^2)).
int reference_insert(std::vector<Observation>& slots, int count, int capacity,
                     const Observation& added) {
  if (count < capacity) {
    slots[count] = added;
    return count + 1;
  }
  auto at = [&](int i) -> const Observation& { return i == capacity ? added : slots[i]; };
  int best_a = 0, best_b = 1;
  float best = -2.0f;
  for (int a = 0; a <= capacity; ++a)
    for (int b = a + 1; b <= capacity; ++b)
      if (at(a).similarity(at(b)) > best) best = at(a).similarity(at(b)), best_a = a, best_b = b;
  const int dropped = at(best_a).frame() <= at(best_b).frame() ? best_a : best_b;
  if (dropped != capacity) slots[dropped] = added;
  return capacity;
}

TEST(Observations, HalfColoursRoundTripWithinHalfAStep) {
  // Exact: zero, powers of two, integers up to 2048, the largest half, the smallest subnormal.
  for (float exact : {0.0f, 1.0f, 0.5f, 0.25f, 3.0f, 2048.0f, 65504.0f, 5.9604645e-08f})
    EXPECT_EQ(float_from_half(half_from_float(exact)), exact) << exact;
  EXPECT_EQ(half_from_float(1.0f), 0x3c00);  // IEEE binary16 bits
  EXPECT_EQ(half_from_float(65504.0f), 0x7bff);
  // Everything else within 2^-11 relative (normal range) or 2^-25 absolute (subnormal range).
  std::mt19937 random(3);
  std::uniform_real_distribution<float> exponent(-30.0f, 15.9f);
  for (int i = 0; i < 100000; ++i) {
    const float value = std::exp2(exponent(random));
    const float back = float_from_half(half_from_float(value));
    EXPECT_LE(std::fabs(back - value), std::max(value * 0x1p-11f, 0x1p-25f)) << value;
  }
  // Out of range: negative and NaN store 0, beyond the largest half stores it.
  EXPECT_EQ(half_from_float(-0.5f), 0);
  EXPECT_EQ(half_from_float(std::nanf("")), 0);
  EXPECT_EQ(float_from_half(half_from_float(1e6f)), 65504.0f);
}

TEST(Observations, StoreColourDirectionAndFrameIn16Bytes) {
  const Eigen::Vector3f colour(0.8f, 0.0123f, 1.7f);
  const Eigen::Vector3f direction = Eigen::Vector3f(0.3f, -0.5f, 0.8f).normalized();
  const Observation o(colour, direction, 123456);
  EXPECT_EQ(sizeof(Observation), 16u);
  EXPECT_EQ(o.frame(), 123456u);
  for (int c = 0; c < 3; ++c) {
    EXPECT_NEAR(o.colour()[c], colour[c], colour[c] * 0x1p-11f);
    EXPECT_NEAR(o.direction()[c], direction[c], 1.6e-5f);
  }
  EXPECT_NEAR(o.similarity(o), 1.0f, 5e-5f);
  const Observation opposite(colour, -direction, 0);
  EXPECT_NEAR(o.similarity(opposite), -1.0f, 5e-5f);
  EXPECT_EQ(o.similarity(opposite), opposite.similarity(o));
  const Observation none;
  EXPECT_EQ(none.colour(), Eigen::Vector3f::Zero());
  EXPECT_EQ(none.direction(), Eigen::Vector3f::UnitZ());
}

TEST(Observations, FillUpToCapacityThenStayFull) {
  Voxel voxel(4);
  for (std::uint32_t f = 0; f < 10; ++f) voxel.insert(seen_from(0.1f * f, 0.7f * f, f));
  EXPECT_EQ(voxel.count, 4);
  Voxel none(0);
  none.insert(seen_from(0, 0, 0));
  EXPECT_EQ(none.count, 0);
}

// Every kernel this CPU can run (scalar, AVX2, AVX-512), not only the one insert_observation()
// picks. Capacities around the vector widths (8, 16) and the largest the slots allow.
TEST(Observations, KeepsTheSameObservationsAsTheBruteForceDefinition) {
  for (const InsertionKernel kernel : supported_insertion_kernels()) {
    std::mt19937 random(7);
    std::uniform_real_distribution<float> theta(0.0f, 1.5f), phi(0.0f, 6.283f);
    for (int capacity : {2, 5, 8, 9, 17, 30, 70, kMaxObservationsPerVoxel}) {
      Voxel voxel(capacity);
      std::vector<Observation> reference(capacity);
      int reference_count = 0;
      for (std::uint32_t f = 0; f < 400; ++f) {
        const Observation o = seen_from(theta(random), phi(random), f);
        voxel.insert(kernel, o);
        reference_count = reference_insert(reference, reference_count, capacity, o);
        ASSERT_EQ(voxel.count, reference_count);
        for (int k = 0; k < capacity && k < voxel.count; ++k)
          ASSERT_EQ(voxel.slots[k].frame(), reference[k].frame())
              << "kernel " << int(kernel) << " capacity " << capacity << " frame " << f;
      }
    }
  }
}

// The kernels agree bit for bit: the same slots, and the same nearest entries (similarities and
// slots), after every insertion.
TEST(Observations, EveryInsertionKernelKeepsTheSameSlotsAndNearestEntries) {
  const std::vector<InsertionKernel> kernels = supported_insertion_kernels();
  ASSERT_EQ(kernels.front(), InsertionKernel::kScalar);
  std::mt19937 random(11);
  std::uniform_real_distribution<float> theta(0.0f, 1.5f), phi(0.0f, 6.283f);
  for (int capacity : {3, 16, 30, 33}) {
    std::vector<Voxel> voxels(kernels.size(), Voxel(capacity));
    for (std::uint32_t f = 0; f < 500; ++f) {
      // Repeats of earlier directions too: ties between equally similar pairs.
      const Observation o =
          f % 7 == 6 ? seen_from(0.5f, 1.0f, f) : seen_from(theta(random), phi(random), f);
      for (std::size_t k = 0; k < kernels.size(); ++k) voxels[k].insert(kernels[k], o);
      for (std::size_t k = 1; k < kernels.size(); ++k) {
        ASSERT_EQ(voxels[k].count, voxels[0].count);
        for (int i = 0; i < voxels[0].count; ++i) {
          ASSERT_EQ(voxels[k].slots[i].frame(), voxels[0].slots[i].frame())
              << "kernel " << int(kernels[k]) << " capacity " << capacity << " frame " << f;
          ASSERT_EQ(voxels[k].similarity[i], voxels[0].similarity[i]);
          ASSERT_EQ(voxels[k].nearest[i], voxels[0].nearest[i]);
        }
      }
    }
  }
}

TEST(Observations, OverflowDropsTheOlderOfTheMostSimilarPair) {
  Voxel voxel(3);
  voxel.insert(seen_from(0.0f, 0.0f, 0));   // top
  voxel.insert(seen_from(1.2f, 0.0f, 1));   // +x grazing
  voxel.insert(seen_from(1.2f, 3.14f, 2));  // -x grazing
  // Nearly the +x direction again: the pair (frame 1, new) is the most similar; frame 1 goes.
  voxel.insert(seen_from(1.15f, 0.05f, 3));
  ASSERT_EQ(voxel.count, 3);
  std::vector<std::uint32_t> frames;
  for (const Observation& o : voxel.slots) frames.push_back(o.frame());
  std::sort(frames.begin(), frames.end());
  EXPECT_EQ(frames, (std::vector<std::uint32_t>{0, 2, 3}));
}

TEST(Observations, RepeatedViewsKeepTheHemisphereCovered) {
  // 30 slots, then 300 observations all from nearly the same direction plus a few others:
  // the few distinct directions must survive (uniform coverage, not recency).
  Voxel voxel(30);
  std::uint32_t frame = 0;
  for (int i = 0; i < 5; ++i) voxel.insert(seen_from(1.0f, 1.25f * i, frame++));
  for (int i = 0; i < 300; ++i) voxel.insert(seen_from(0.05f + 0.0001f * i, 0.0f, frame++));
  int distinct = 0;
  for (int k = 0; k < voxel.count; ++k) distinct += voxel.slots[k].frame() < 5;
  EXPECT_EQ(distinct, 5);
}

}  // namespace
}  // namespace glint::reflectance
