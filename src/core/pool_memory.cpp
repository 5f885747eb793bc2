#include "core/pool_memory.h"

#include <sys/mman.h>

#include <cerrno>
#include <cstdint>
#include <cstring>
#include <limits>
#include <string>

#include "core/error.h"

namespace glint {

namespace {
constexpr std::size_t kHugePage = std::size_t{2} << 20;
}

void PoolDeleter::operator()(void* array) const {
  if (array) munmap(mapping, mapped_bytes);
}

void* detail::map_pool(std::size_t count, std::size_t element_bytes, const char* what,
                       PoolDeleter& deleter) {
  const auto cannot_reserve = [&](const std::string& why) {
    return Error(what, "",
                 "cannot reserve " + std::to_string(count) + " elements of " +
                     std::to_string(element_bytes) + " bytes: " + why);
  };
  if (count > (std::numeric_limits<std::size_t>::max() - 2 * kHugePage) / element_bytes)
    throw cannot_reserve("larger than the address space");
  const std::size_t bytes = count * element_bytes;
  // Huge pages back only whole 2 MiB-aligned stretches of the advised range, so large pools
  // reserve whole huge pages and one more, start at the first aligned address and advise up to
  // the last whole page (a pool's tail on 4 KiB pages faults once per page on first touch).
  const bool huge = bytes >= kHugePage;
  const std::size_t huge_bytes = (bytes + kHugePage - 1) / kHugePage * kHugePage;
  const std::size_t mapped_bytes = huge ? huge_bytes + kHugePage : bytes;
  void* mapping = mmap(nullptr, mapped_bytes, PROT_READ | PROT_WRITE,
                       MAP_PRIVATE | MAP_ANONYMOUS | MAP_NORESERVE, -1, 0);
  if (mapping == MAP_FAILED) throw cannot_reserve(std::strerror(errno));
  deleter = {mapping, mapped_bytes};
  if (!huge) return mapping;
  const auto start = (reinterpret_cast<std::uintptr_t>(mapping) + kHugePage - 1) & ~(kHugePage - 1);
  void* array = reinterpret_cast<void*>(start);
#if defined(MADV_HUGEPAGE)
  madvise(array, huge_bytes, MADV_HUGEPAGE);
#endif
  return array;
}

}  // namespace glint
