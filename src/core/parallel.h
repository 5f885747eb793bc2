#pragma once
// Data-parallel loops over elements (points, pixels, voxels) on TBB's thread pool.
#include <tbb/blocked_range.h>
#include <tbb/global_control.h>
#include <tbb/parallel_for.h>

#include <cstddef>
#include <memory>

namespace glint {

// Calls body(i) for every i in [0, n), in parallel. body must be safe to call concurrently.
template <class Body>
void parallel_for(std::size_t n, Body&& body) {
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n),
                    [&](const tbb::blocked_range<std::size_t>& range) {
                      for (std::size_t i = range.begin(); i != range.end(); ++i) body(i);
                    });
}

// Calls body(begin, end) on disjoint chunks of [0, n) of about `grain` elements, in parallel:
// use it when a chunk shares scratch memory or set-up work.
template <class Body>
void parallel_for_chunks(std::size_t n, std::size_t grain, Body&& body) {
  tbb::parallel_for(
      tbb::blocked_range<std::size_t>(0, n, grain),
      [&](const tbb::blocked_range<std::size_t>& range) { body(range.begin(), range.end()); });
}

// Limits TBB to `threads` worker threads for the lifetime of the returned object (0 = all).
inline std::unique_ptr<tbb::global_control> limit_threads(int threads) {
  if (threads <= 0) return nullptr;
  return std::make_unique<tbb::global_control>(tbb::global_control::max_allowed_parallelism,
                                               static_cast<std::size_t>(threads));
}

}  // namespace glint
