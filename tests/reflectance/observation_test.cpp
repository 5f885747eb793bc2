#include "reflectance/observation.h"

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

namespace glint::reflectance {
namespace {

Observation seen_from(float theta, float phi, std::uint32_t frame) {
  Observation o;
  o.direction = {std::sin(theta) * std::cos(phi), std::sin(theta) * std::sin(phi), std::cos(theta)};
  o.colour = Eigen::Vector3f::Constant(float(frame));
  o.frame = frame;
  return o;
}

TEST(Observations, FillUpToCapacityThenStayFull) {
  std::vector<Observation> slots(4);
  int count = 0;
  for (std::uint32_t f = 0; f < 10; ++f)
    count = insert_observation(slots.data(), count, 4, seen_from(0.1f * f, 0.7f * f, f));
  EXPECT_EQ(count, 4);
  EXPECT_EQ(insert_observation(slots.data(), 0, 0, seen_from(0, 0, 0)), 0);
}

TEST(Observations, OverflowDropsTheOlderOfTheMostSimilarPair) {
  std::vector<Observation> slots(3);
  int count = 0;
  count = insert_observation(slots.data(), count, 3, seen_from(0.0f, 0.0f, 0));   // top
  count = insert_observation(slots.data(), count, 3, seen_from(1.2f, 0.0f, 1));   // +x grazing
  count = insert_observation(slots.data(), count, 3, seen_from(1.2f, 3.14f, 2));  // -x grazing
  // Nearly the +x direction again: the pair (frame 1, new) is the most similar; frame 1 goes.
  count = insert_observation(slots.data(), count, 3, seen_from(1.15f, 0.05f, 3));
  ASSERT_EQ(count, 3);
  std::vector<std::uint32_t> frames;
  for (const Observation& o : slots) frames.push_back(o.frame);
  std::sort(frames.begin(), frames.end());
  EXPECT_EQ(frames, (std::vector<std::uint32_t>{0, 2, 3}));
}

TEST(Observations, RepeatedViewsKeepTheHemisphereCovered) {
  // 30 slots, then 300 observations all from nearly the same direction plus a few others:
  // the few distinct directions must survive (uniform coverage, not recency).
  const int capacity = 30;
  std::vector<Observation> slots(capacity);
  int count = 0;
  std::uint32_t frame = 0;
  for (int i = 0; i < 5; ++i)
    count = insert_observation(slots.data(), count, capacity, seen_from(1.0f, 1.25f * i, frame++));
  for (int i = 0; i < 300; ++i)
    count = insert_observation(slots.data(), count, capacity,
                               seen_from(0.05f + 0.0001f * i, 0.0f, frame++));
  int distinct = 0;
  for (int k = 0; k < count; ++k) distinct += slots[k].frame < 5;
  EXPECT_EQ(distinct, 5);
}

}  // namespace
}  // namespace glint::reflectance
