// Voxel and observation pools: zero-filled, writable, huge-page aligned, clear errors.
#include "core/pool_memory.h"

#include <gtest/gtest.h>

#include <cstdint>

#include "core/error.h"
#include "support/error_of.h"

namespace glint {
namespace {

TEST(PoolMemory, PoolsAreZeroFilledAndWritable) {
  for (std::size_t count : {std::size_t{2}, std::size_t{1000}, std::size_t{3} << 20}) {
    PoolArray<float> pool = make_pool<float>(count, "test pool");
    ASSERT_NE(pool.get(), nullptr);
    EXPECT_EQ(pool[0], 0.0f);
    EXPECT_EQ(pool[count - 1], 0.0f);
    pool[0] = 2.5f;
    pool[count - 1] = -1.0f;
    EXPECT_EQ(pool[0], 2.5f);
    EXPECT_EQ(pool[count - 1], -1.0f);
  }
  EXPECT_NE(make_pool<double>(0, "empty pool").get(), nullptr) << "one element at least";
}

TEST(PoolMemory, PoolsOfHugePagesStartOnAHugePageBoundary) {
  // 5 MiB, and a size that is no whole number of pages: the tail is as usable as the start.
  for (std::size_t bytes : {std::size_t{5} << 20, (std::size_t{3} << 20) + 4097}) {
    PoolArray<std::uint8_t> pool = make_pool<std::uint8_t>(bytes, "test pool");
    EXPECT_EQ(reinterpret_cast<std::uintptr_t>(pool.get()) % (std::size_t{2} << 20), 0u);
    EXPECT_EQ(pool[bytes - 1], 0u);
    pool[bytes - 1] = 7;
    EXPECT_EQ(pool[bytes - 1], 7u);
  }
}

TEST(PoolMemory, AnUnreservableSizeIsAnErrorNamingThePool) {
  // 2^60 doubles: more than the address space holds; 2^62: the byte count overflows.
  for (std::size_t count : {std::size_t{1} << 60, std::size_t{1} << 62}) {
    const Error error = test::error_of([&] { make_pool<double>(count, "huge pool"); });
    EXPECT_EQ(error.file(), "huge pool");
    EXPECT_NE(error.reason().find("cannot reserve"), std::string::npos) << error.reason();
  }
}

}  // namespace
}  // namespace glint
