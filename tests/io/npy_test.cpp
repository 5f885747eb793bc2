// NumPy .npy arrays and .npy images: round trips (any channel count), the float64 and version
// 2.0 variants, and malformed files.
#include "io/npy.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "core/error.h"
#include "io/image_io.h"
#include "io_test_support.h"

namespace glint::io {
namespace {

using test::error_of;
using test::read_text;
using test::scratch;
using test::write_text;
using ::testing::HasSubstr;

// A hand-made .npy: magic, version, little-endian header length, header, data.
std::string npy_file(int major, const std::string& header, const std::string& data) {
  std::string bytes = "\x93NUMPY";
  bytes += static_cast<char>(major);
  bytes += '\0';
  const std::size_t length = header.size();
  const int length_bytes = major == 1 ? 2 : 4;
  for (int i = 0; i < length_bytes; ++i) bytes += static_cast<char>((length >> (8 * i)) & 0xff);
  return bytes + header + data;
}

std::string doubles(std::initializer_list<double> values) {
  std::string data;
  for (double v : values) data.append(reinterpret_cast<const char*>(&v), sizeof v);
  return data;
}

TEST(Npy, RoundTripsAnyShape) {
  const std::string path = scratch("array.npy");
  const std::vector<float> values{1.5f, -2.f, 3.25f, 0.f, 1e-7f, 42.f};
  write_npy(path, {2, 3}, values.data());
  const NpyArray array = read_npy(path);
  EXPECT_EQ(array.shape, (std::vector<std::size_t>{2, 3}));
  EXPECT_EQ(array.values, values);
  EXPECT_EQ(read_text(path).size() % 64, 24u);  // header padded to 64 bytes, then 6 floats
}

TEST(Npy, ReadsFloat64AndVersion2) {
  const std::string path = scratch("f8.npy");
  write_text(path, npy_file(2, "{'descr': '<f8', 'fortran_order': False, 'shape': (3,), }\n",
                            doubles({0.5, -1.0, 2.0})));
  const NpyArray array = read_npy(path);
  EXPECT_EQ(array.shape, (std::vector<std::size_t>{3}));
  EXPECT_EQ(array.values, (std::vector<float>{0.5f, -1.f, 2.f}));
}

// A zero extent is a valid empty array (fuzz/corpus/npy/regression-zero-extent once passed a
// null buffer to memcpy); as an image it has no pixels.
TEST(Npy, ZeroExtentGivesAnEmptyArray) {
  const std::string path = scratch("empty.npy");
  write_text(path,
             npy_file(1, "{'descr': '<f4', 'fortran_order': False, 'shape': (0, 3, 4), }\n", ""));
  const NpyArray array = read_npy(path);
  EXPECT_EQ(array.shape, (std::vector<std::size_t>{0, 3, 4}));
  EXPECT_TRUE(array.values.empty());
  EXPECT_THAT(error_of([&] { read_image(path); }).reason(), HasSubstr("pixels"));
}

TEST(Npy, MalformedFilesNameTheProblem) {
  const std::string header = "{'descr': '<f8', 'fortran_order': False, 'shape': (2, 2), }\n";
  const std::string truncated = scratch("truncated.npy");
  write_text(truncated, npy_file(1, header, doubles({1, 2, 3})));
  EXPECT_THAT(error_of([&] { read_npy(truncated); }).reason(), HasSubstr("truncated"));

  const std::string ints = scratch("ints.npy");
  write_text(ints, npy_file(1, "{'descr': '<i4', 'fortran_order': False, 'shape': (1,), }\n",
                            std::string(4, '\0')));
  EXPECT_THAT(error_of([&] { read_npy(ints); }).reason(), HasSubstr("<i4"));

  const std::string fortran = scratch("fortran.npy");
  write_text(fortran, npy_file(1, "{'descr': '<f8', 'fortran_order': True, 'shape': (1,), }\n",
                               doubles({1})));
  EXPECT_THAT(error_of([&] { read_npy(fortran); }).reason(), HasSubstr("Fortran"));

  // An extent beyond 64 bits, and a header longer than NumPy itself accepts.
  const std::string huge = scratch("huge.npy");
  write_text(huge, npy_file(1, "{'descr': '<f4', 'shape': (99999999999999999999999,), }\n", ""));
  EXPECT_EQ(error_of([&] { read_npy(huge); }).reason(), "shape is implausibly large");
  const std::string padded = scratch("padded.npy");
  write_text(padded, npy_file(2, "{'descr': '<f4', 'shape': (1,), }" + std::string(20000, ' '),
                              std::string(4, '\0')));
  EXPECT_EQ(error_of([&] { read_npy(padded); }).reason(),
            "the header is 20033 bytes long, more than NumPy's limit of 10000");

  const std::string text = scratch("text.npy");
  write_text(text, "hello");
  EXPECT_EQ(error_of([&] { read_npy(text); }).file(), text);
}

TEST(NpyImage, FiveChannelMaterialMapRoundTrips) {
  ImageF image(4, 3, 5);
  for (std::size_t i = 0; i < image.values().size(); ++i) image.values()[i] = 0.1f * i - 2.f;
  const std::string path = scratch("material.npy");
  write_image(path, image);
  const NpyArray raw = read_npy(path);
  EXPECT_EQ(raw.shape, (std::vector<std::size_t>{3, 4, 5}));  // (height, width, channels)
  EXPECT_FLOAT_EQ(raw.values[(2 * 4 + 1) * 5 + 3], image.at(1, 2, 3));
  const ImageF back = read_image(path);
  EXPECT_EQ(back.channels(), 5);
  EXPECT_EQ(back.values(), image.values());
  // PNG and EXR stay limited to 1, 3 or 4 channels, and say what to use instead.
  EXPECT_THAT(error_of([&] { write_image(scratch("material.exr"), image); }).reason(),
              HasSubstr(".npy"));
}

TEST(NpyImage, WrongRankIsAnError) {
  const std::string path = scratch("rank4.npy");
  const std::vector<float> values(16, 0.f);
  write_npy(path, {2, 2, 2, 2}, values.data());
  EXPECT_THAT(error_of([&] { read_image(path); }).reason(), HasSubstr("height, width"));
}

}  // namespace
}  // namespace glint::io
