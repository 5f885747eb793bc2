// core/limits.h: each check names the file, the field and the allowed range; an allocation too
// large for the machine says what it was for and how big, not a bare std::bad_alloc.
#include "core/limits.h"

#include <gtest/gtest.h>

#include "core/point_cloud.h"
#include "support/error_of.h"

namespace glint::limits {
namespace {

using glint::test::error_of;

TEST(Limits, PositionsOutsideTheWorldExtent) {
  EXPECT_NO_THROW(check_position({1e5, -1e5, 0}, "f", "p"));
  const Error far = error_of([] { check_position({0, 2e5, 0}, "scene.json", "camera"); });
  EXPECT_EQ(far.file(), "scene.json");
  EXPECT_EQ(far.element(), "camera");
  EXPECT_EQ(far.reason(), "coordinate 200000 is outside the world extent [-100000, 100000] m");
  EXPECT_THROW(check_position({0, 0, std::nan("")}, "f", "p"), Error);
}

TEST(Limits, IntrinsicsAgainstTheImageSize) {
  EXPECT_NO_THROW(check_intrinsics({640, 480, 525, 525, 319.5, 239.5}, "k.txt", "K"));
  const Error cx = error_of([] {
    check_intrinsics({640, 480, 525, 525, 1e9, 239.5}, "k.txt", "K");
  });
  EXPECT_EQ(cx.element(), "K.cx");
  EXPECT_EQ(cx.reason(), "1000000000 is outside the allowed range [0, 640] for a 640x480 image");
  const Error fx = error_of([] { check_intrinsics({640, 480, -525, 525, 320, 240}, "k", ""); });
  EXPECT_EQ(fx.element(), "fx");
  EXPECT_EQ(fx.reason(), "-525 is outside the allowed range (0, 640000] for a 640x480 image");
  const Error size = error_of([] { check_intrinsics({0, 480, 525, 525, 0, 0}, "k", "K"); });
  EXPECT_EQ(size.element(), "K");
}

TEST(Limits, ImageSizesAndIntegers) {
  EXPECT_NO_THROW(check_image_size(16384, 8192, "a.png", "header"));
  EXPECT_THROW(check_image_size(16385, 8192, "a.png", "header"), Error);
  EXPECT_THROW(check_image_size(70000, 1, "a.png", "header"), Error);
  EXPECT_NO_THROW(check_integer(3, 1, 3, "f", "n"));
  const Error error = error_of([] { check_integer(2e9, 1, 65536, "scene.json", "samples"); });
  EXPECT_EQ(error.reason(), "2000000000 is not an integer in the allowed range [1, 65536]");
  EXPECT_THROW(check_integer(1.5, 1, 3, "f", "n"), Error);
}

TEST(Limits, ImpossibleAllocationSaysWhatAndHowBig) {
  PointCloud cloud;
  const Error error = error_of([&] { cloud.resize(std::size_t(1) << 62); });
  EXPECT_EQ(error.element(), "a cloud of 4611686018427387904 points");
  EXPECT_EQ(error.reason(),
            "out of memory: it needs 52776558133248 MiB, more than this machine could give");
}

}  // namespace
}  // namespace glint::limits
