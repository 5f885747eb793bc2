// LAS reading and pass-through writing: every point format with extra bytes, VLRs and EVLRs
// kept byte for byte, and one clear error for each kind of corrupt or truncated file.
#include "io/las.h"

#include <gtest/gtest.h>

#include <cstring>
#include <filesystem>
#include <fstream>
#include <random>

#include "io/io_test_support.h"

namespace glint::io {
namespace {

using glint::test::error_of;
using test::scratch;

std::vector<std::uint8_t> file_bytes(const std::string& path) {
  std::ifstream stream(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(stream), {}};
}
void write_bytes(const std::string& path, const std::vector<std::uint8_t>& bytes) {
  std::ofstream(path, std::ios::binary)
      .write(reinterpret_cast<const char*>(bytes.data()), std::streamsize(bytes.size()));
}

std::vector<std::uint8_t> vlr(const char* user, std::uint16_t record_id,
                              const std::vector<std::uint8_t>& payload) {
  std::vector<std::uint8_t> bytes(54 + payload.size(), 0);
  std::memcpy(bytes.data() + 2, user, std::strlen(user));
  std::memcpy(bytes.data() + 18, &record_id, 2);
  const auto length = static_cast<std::uint16_t>(payload.size());
  std::memcpy(bytes.data() + 20, &length, 2);
  std::copy(payload.begin(), payload.end(), bytes.begin() + 54);
  return bytes;
}

// A file of `n` points in `format` whose records carry random bytes, a described "my_short"
// (ushort) and one undescribed extra byte; a foreign VLR before the Extra Bytes one, and (1.4)
// one EVLR. Returns the records.
std::vector<std::uint8_t> write_test_las(const std::string& path, int format, std::size_t n,
                                         std::uint64_t seed, const double offset[3] = nullptr) {
  const int minor = format >= 6 ? 4 : format >= 4 ? 3 : 2;
  const double scale[3] = {0.01, 0.01, 0.001};
  const double zero[3] = {0, 0, 0};
  const double* shift = offset ? offset : zero;
  const double low[3] = {shift[0] - 10, shift[1] - 10, shift[2] - 1};
  const double high[3] = {shift[0] + 10, shift[1] + 10, shift[2] + 1};
  LasHeader header = make_las_header(minor, format, 3, n, scale, offset ? offset : zero, low, high);
  std::vector<std::uint8_t> descriptor(192, 0);
  descriptor[2] = 3;  // ushort
  std::memcpy(descriptor.data() + 4, "my_short", 8);
  const auto foreign = vlr("someone", 7, {1, 2, 3, 4, 5});
  const auto extra = vlr("LASF_Spec", 4, descriptor);
  header.vlr_bytes = foreign;
  header.vlr_bytes.insert(header.vlr_bytes.end(), extra.begin(), extra.end());
  header.vlr_bytes.push_back(0xAB);  // a stray byte before the point data
  header.vlr_count = 2;
  header.offset_to_points = header.header_bytes.size() + header.vlr_bytes.size();
  if (minor >= 4) {
    std::vector<std::uint8_t> evlr(60 + 11, 0x5A);
    const std::uint64_t length = 11;
    std::memcpy(evlr.data() + 20, &length, 8);
    header.evlr_bytes = evlr;
    header.evlr_count = 1;
    header.evlr_start = header.offset_to_points + n * header.record_length;
    const std::uint32_t count = 1;
    std::memcpy(header.header_bytes.data() + 243, &count, 4);
  }
  std::vector<std::uint8_t> records(n * header.record_length);
  std::mt19937_64 rng(seed);
  for (auto& byte : records) byte = static_cast<std::uint8_t>(rng());
  for (std::size_t i = 0; i < n; ++i) {
    // Coordinates inside the bounds.
    const std::int32_t xyz[3] = {std::int32_t(rng() % 2000) - 1000,
                                 std::int32_t(rng() % 2000) - 1000,
                                 std::int32_t(rng() % 2000) - 1000};
    std::memcpy(records.data() + i * header.record_length, xyz, 12);
  }
  LasWriter writer(path, "test", header, true);
  writer.write_records(0, n, records.data());
  writer.commit();
  return records;
}

class LasFormats : public ::testing::TestWithParam<int> {};

TEST_P(LasFormats, RoundTripKeepsEveryByteAndAddsExtraBytes) {
  const int format = GetParam();
  const std::string in = scratch("in.las"), out = scratch("out.las");
  const std::size_t n = 37;
  const std::vector<std::uint8_t> records = write_test_las(in, format, n, 10 + format);

  const LasReader reader(in);
  const LasHeader& header = reader.header();
  EXPECT_EQ(header.point_format, format);
  EXPECT_EQ(header.point_count, n);
  EXPECT_EQ(header.record_length, las_min_record_length(format) + 3);
  ASSERT_EQ(header.extra_fields.size(), 1u);
  EXPECT_EQ(header.extra_fields[0].name, "my_short");
  EXPECT_EQ(header.extra_fields[0].offset, las_min_record_length(format));
  std::vector<std::uint8_t> read_back(records.size());
  reader.read_records(0, n, read_back.data());
  EXPECT_EQ(read_back, records);

  LasBoundedFields fields;
  const LasHeader out_header = las_header_with_bounded_fields(header, in, fields);
  EXPECT_TRUE(fields.appended);
  EXPECT_EQ(out_header.record_length, header.record_length + 9);
  {
    LasWriter writer(out, "test", out_header, true);
    std::vector<std::uint8_t> output(n * out_header.record_length);
    for (std::size_t i = 0; i < n; ++i) {
      std::uint8_t* record = output.data() + i * out_header.record_length;
      std::memcpy(record, records.data() + i * header.record_length, header.record_length);
      las_set_bounded_fields(record, fields, std::uint8_t(i % 3), 0.25f * float(i), -1.0f);
    }
    writer.write_records(0, n, output.data());
    writer.commit();
  }
  EXPECT_FALSE(std::filesystem::exists(out + ".tmp-test"));

  const LasReader result(out);
  const LasHeader& h = result.header();
  EXPECT_EQ(h.point_count, n);
  EXPECT_EQ(h.vlr_count, 2u);            // ours joined the existing Extra Bytes VLR
  ASSERT_EQ(h.extra_fields.size(), 5u);  // my_short, the undescribed byte, our three
  EXPECT_EQ(h.extra_fields[1].size, 1u);
  EXPECT_EQ(h.find_extra("bounded_label")->offset, header.record_length);
  EXPECT_EQ(h.find_extra("p_sharp")->data_type, 9);
  EXPECT_EQ(h.evlr_bytes, header.evlr_bytes);
  // The foreign VLR and the stray byte are still there.
  EXPECT_TRUE(
      std::equal(header.vlr_bytes.begin(), header.vlr_bytes.begin() + 59, h.vlr_bytes.begin()));
  EXPECT_EQ(h.vlr_bytes.back(), 0xAB);
  std::vector<std::uint8_t> output(n * h.record_length);
  result.read_records(0, n, output.data());
  for (std::size_t i = 0; i < n; ++i) {
    const std::uint8_t* record = output.data() + i * h.record_length;
    EXPECT_EQ(std::memcmp(record, records.data() + i * header.record_length, header.record_length),
              0)
        << "point " << i;
  }
  // Header fields other than the layout (scale, offset, bounds, identifiers) are unchanged.
  const std::vector<std::uint8_t> in_bytes = file_bytes(in), out_bytes = file_bytes(out);
  EXPECT_TRUE(std::equal(in_bytes.begin() + 131, in_bytes.begin() + 227, out_bytes.begin() + 131));

  const PointCloud cloud = read_las(out);
  ASSERT_EQ(cloud.size(), n);
  const auto* labels = cloud.get<std::uint8_t>("scalar_label");
  const auto* p_sharp = cloud.get<float>("scalar_p_sharp");
  ASSERT_TRUE(labels && p_sharp && cloud.get<std::uint16_t>("my_short"));
  EXPECT_EQ((*labels)[5], 2);
  EXPECT_EQ((*p_sharp)[4], 1.0f);

  // Classifying the output again writes in place: same layout.
  LasBoundedFields again;
  const LasHeader same = las_header_with_bounded_fields(h, out, again);
  EXPECT_FALSE(again.appended);
  EXPECT_EQ(same.record_length, h.record_length);
  EXPECT_EQ(again.label_offset, fields.label_offset);
}

INSTANTIATE_TEST_SUITE_P(EveryPointFormat, LasFormats, ::testing::Range(0, 11));

TEST(Las, RecentringDoesNotDependOnTheOffset) {
  const std::string near = scratch("near.las"), far = scratch("far.las");
  const double far_offset[3] = {1.0e6 + 0.37, 5.0e6 + 0.11, 312.5};
  write_test_las(near, 1, 50, 3);
  write_test_las(far, 1, 50, 3, far_offset);
  const PointCloud a = read_las(near), b = read_las(far);
  EXPECT_EQ(a.x, b.x);
  EXPECT_EQ(a.y, b.y);
  EXPECT_EQ(a.z, b.z);
}

// Each corruption: one error naming the file, the field and the problem.
struct Corruption {
  const char* name;
  std::size_t position;  // byte to overwrite (SIZE_MAX: truncate to `value` bytes instead)
  std::vector<std::uint8_t> bytes;
  std::size_t truncate_to;
  const char* field;
  const char* reason_part;
};

TEST(Las, CorruptAndTruncatedFilesGiveOneClearError) {
  const std::string good = scratch("good.las");
  write_test_las(good, 6, 20, 1);
  const std::vector<std::uint8_t> original = file_bytes(good);
  const LasHeader header = LasReader(good).header();
  const std::size_t points_at = header.offset_to_points;
  const std::size_t extra_vlr_at = 375 + 59;
  const std::vector<Corruption> cases = {
      {"signature", 0, {'X'}, 0, "file signature", "not a LAS file"},
      {"version", 25, {9}, 0, "version", "not supported"},
      {"header size", 94, {100, 0}, 0, "header size", "needs at least 375"},
      {"laz", 104, {0x86}, 0, "point data format", "laszip"},
      {"format", 104, {11}, 0, "point data format", "0 to 10"},
      {"record length", 105, {10, 0}, 0, "point data record length", "shorter"},
      {"offset", 96, {0xFF, 0xFF, 0xFF, 0x7F}, 0, "offset to point data", "outside"},
      {"vlr count", 100, {9}, 0, "VLR 2", "point data"},
      {"vlr length", extra_vlr_at + 20, {0xFF, 0x0F}, 0, "VLR 1 ('LASF_Spec' 4)", "run past"},
      {"extra bytes type",
       extra_vlr_at + 54 + 2,
       {99},
       0,
       "Extra Bytes descriptor 0 ('my_short')",
       "unknown data type"},
      {"scale", 131, std::vector<std::uint8_t>(8, 0), 0, "x scale factor / offset", "positive"},
      {"points", SIZE_MAX, {}, points_at + 5 * header.record_length + 3, "point data", "truncated"},
      {"header", SIZE_MAX, {}, 100, "public header", "truncated"},
      {"evlr", SIZE_MAX, {}, original.size() - 4, "EVLR 0", "truncated"},
  };
  for (const Corruption& c : cases) {
    std::vector<std::uint8_t> bytes = original;
    if (c.position == SIZE_MAX) {
      bytes.resize(c.truncate_to);
    } else {
      std::copy(c.bytes.begin(), c.bytes.end(), bytes.begin() + std::ptrdiff_t(c.position));
    }
    const std::string path = scratch(std::string("bad-") + c.name + ".las");
    write_bytes(path, bytes);
    const Error e = error_of([&] { LasReader reader(path); });
    EXPECT_EQ(e.file(), path) << c.name;
    EXPECT_EQ(e.element(), c.field) << c.name << ": " << e.what();
    EXPECT_NE(e.reason().find(c.reason_part), std::string::npos) << c.name << ": " << e.what();
    EXPECT_EQ(std::string(e.what()).find('\n'), std::string::npos);
  }
}

TEST(Las, LazIsRefusedWithHowToDecompress) {
  const std::string path = scratch("scan.laz");
  write_bytes(path, {'L', 'A', 'S', 'F'});
  const Error e = error_of([&] { LasReader reader(path); });
  EXPECT_NE(e.reason().find("laszip -i"), std::string::npos) << e.what();
  EXPECT_NE(e.reason().find("pdal translate"), std::string::npos) << e.what();
}

TEST(Las, PartialBoundedFieldsAreRefused) {
  const std::string path = scratch("partial.las");
  write_test_las(path, 0, 5, 2);
  LasHeader header = LasReader(path).header();
  header.extra_fields[0].name = "p_sharp";
  LasBoundedFields fields;
  const Error e = error_of([&] { las_header_with_bounded_fields(header, path, fields); });
  EXPECT_EQ(e.element(), "Extra Bytes VLR");
}

}  // namespace
}  // namespace glint::io
