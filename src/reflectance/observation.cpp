#include "reflectance/observation.h"

namespace glint::reflectance {

int insert_observation(Observation* slots, int count, int capacity, const Observation& added) {
  if (capacity <= 0) return 0;
  if (count < capacity) {
    slots[count] = added;
    return count + 1;
  }
  // Slot index `capacity` stands for the new observation.
  auto at = [&](int i) -> const Observation& { return i == capacity ? added : slots[i]; };
  int best_a = 0, best_b = 1;
  float best_similarity = -2.0f;
  for (int a = 0; a <= capacity; ++a)
    for (int b = a + 1; b <= capacity; ++b) {
      const float similarity = at(a).direction.dot(at(b).direction);
      if (similarity > best_similarity) {
        best_similarity = similarity;
        best_a = a;
        best_b = b;
      }
    }
  // best_a < best_b; the new observation (index capacity) is never older than a stored one.
  const int dropped = at(best_a).frame <= at(best_b).frame ? best_a : best_b;
  if (dropped != capacity) slots[dropped] = added;
  return capacity;
}

}  // namespace glint::reflectance
