#pragma once
// Large, zero-filled, lazily committed arrays for voxel and observation pools. The pools are
// reserved at their full capacity once and touched in scattered blocks every frame; on 4 KiB
// pages nearly every block access misses the TLB, so pools of 2 MiB or more ask the kernel for
// transparent huge pages (madvise; a hint the kernel may ignore, e.g. with THP off).
#include <algorithm>
#include <cstddef>
#include <memory>
#include <type_traits>

namespace glint {

// Unmaps the whole reservation (which may start before the array, see map_pool()).
struct PoolDeleter {
  void* mapping = nullptr;
  std::size_t mapped_bytes = 0;
  void operator()(void* array) const;
};

template <class T>
using PoolArray = std::unique_ptr<T[], PoolDeleter>;

// Asks for the cache lines of [p, p + bytes) ahead of use: a frame's blocks lie scattered in the
// pools, so the hardware prefetcher cannot guess them.
inline void prefetch_lines(const void* p, std::size_t bytes) {
  constexpr std::size_t kLine = 64;
  const auto* first = static_cast<const char*>(p);
  for (std::size_t offset = 0; offset < bytes; offset += kLine) __builtin_prefetch(first + offset);
  if (bytes > 0) __builtin_prefetch(first + bytes - 1);
}

namespace detail {
// Maps zero-filled memory for `count` elements of `element_bytes` (pages committed on first
// touch) and returns the array's start; `deleter` learns what to unmap. Throws glint::Error
// naming `what` when the address space cannot be reserved.
void* map_pool(std::size_t count, std::size_t element_bytes, const char* what,
               PoolDeleter& deleter);
}  // namespace detail

// `count` zero-filled elements, for types whose all-zero bytes are a valid value (the pools hold
// plain data; a pool of atomics is constructed by its owner, see VoxelBlockHash).
template <class T>
PoolArray<T> make_pool(std::size_t count, const char* what) {
  static_assert(std::is_trivially_destructible_v<T>);
  PoolDeleter deleter;
  T* array =
      static_cast<T*>(detail::map_pool(std::max<std::size_t>(count, 1), sizeof(T), what, deleter));
  return PoolArray<T>(array, deleter);
}

}  // namespace glint
