#pragma once
// LAS 1.2-1.4 point clouds (ASPRS LAS specification 1.4 R15): little-endian, uncompressed,
// point data record formats 0-10, read and written record by record so that a file never has
// to fit in memory.
//
// glint never rewrites a point's own fields: records are kept as raw bytes, so every field
// (Classification included), every VLR and every 1.4 EVLR passes through unchanged. Its
// results are added as Extra Bytes (LAS 1.4 §2.6, the LASF_Spec / 4 VLR) appended to each record,
// or written in place when the input already carries fields of the same names and types.
//
// Coordinates: a record stores integers X, Y, Z; the position is X * scale + offset (double).
// glint re-centres on an integer origin in record units before converting to float, so that
// float((X - origin_x) * scale_x) does not depend on the file's offset: a survey at 10^6 m
// easting gives exactly the floats of the same survey at the origin.
//
// LAZ (compressed LAS) is refused with a message saying how to decompress it.
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "core/point_cloud.h"

namespace glint::io {

// One Extra Bytes field of a record (LAS 1.4 Table 24).
struct LasExtraField {
  std::string name;
  int data_type = 0;       // 1 uchar, 2 char, 3 ushort, 4 short, 5 ulong, 6 long,
                           // 7 ulonglong, 8 longlong, 9 float, 10 double; 0 = opaque bytes
  std::size_t size = 0;    // bytes per record
  std::size_t offset = 0;  // from the start of the record
};

// Everything of a LAS file except its point records.
struct LasHeader {
  int version_minor = 2;  // 1.<minor>
  int point_format = 0;   // 0..10
  std::size_t record_length = 0;
  std::uint64_t point_count = 0;
  double scale[3] = {0.001, 0.001, 0.001};
  double offset[3] = {0, 0, 0};
  double min[3] = {0, 0, 0};
  double max[3] = {0, 0, 0};
  std::uint64_t offset_to_points = 0;
  std::uint32_t vlr_count = 0;
  std::uint64_t evlr_start = 0;  // 1.4: absolute offset of the first EVLR (0 = none)
  std::uint32_t evlr_count = 0;
  std::vector<std::uint8_t> header_bytes;  // the public header, as read
  std::vector<std::uint8_t> vlr_bytes;     // the bytes between it and the point data (VLRs)
  std::vector<std::uint8_t> evlr_bytes;    // 1.4 EVLRs after the point data
  std::vector<LasExtraField> extra_fields;

  const LasExtraField* find_extra(const std::string& name) const;
};

// Minimum record length of a point data record format (20 for format 0 ... 67 for format 10).
std::size_t las_min_record_length(int point_format);

// Reads a LAS file's header, VLRs and EVLRs and then its records on demand (thread-safe reads
// at any position). Throws glint::Error(path, field, problem) for LAZ, unsupported versions or
// formats, and any corrupt or truncated header, VLR, Extra Bytes description, point data or
// EVLR, before a single point is read.
class LasReader {
 public:
  explicit LasReader(std::string path);
  ~LasReader();
  LasReader(const LasReader&) = delete;
  LasReader& operator=(const LasReader&) = delete;

  const std::string& path() const { return path_; }
  const LasHeader& header() const { return header_; }
  // Copies records [first, first + count) to `records` (count * record_length bytes).
  void read_records(std::uint64_t first, std::size_t count, std::uint8_t* records) const;

 private:
  std::string path_;
  int fd_ = -1;
  LasHeader header_;
};

// The integer X, Y, Z of a record (every format starts with them).
void las_record_xyz(const std::uint8_t* record, std::int32_t xyz[3]);

// glint's per-point outputs as Extra Bytes: uchar bounded_label, float p_sharp, float
// p_boundary (9 bytes a record).
struct LasBoundedFields {
  std::size_t label_offset = 0, p_sharp_offset = 0, p_boundary_offset = 0;
  bool appended = true;  // false: the input already had them and they are overwritten
};

// The output header of a pass-through that adds glint's fields: the same header and VLRs with
// the three descriptors added to the Extra Bytes VLR (one is created when missing), the record
// length grown by 9 and the offsets after it moved; or the input's own layout when it already
// carries the three fields with these types. Throws glint::Error when it carries some of them,
// or with other types.
LasHeader las_header_with_bounded_fields(const LasHeader& input, const std::string& input_path,
                                         LasBoundedFields& fields);

// Writes the fields of one point into its output record.
void las_set_bounded_fields(std::uint8_t* record, const LasBoundedFields& fields,
                            std::uint8_t label, float p_sharp, float p_boundary);

// A LAS file written at known positions, so that several threads or processes can fill its
// records in any order. The data go to "<path>.tmp-<tag>"; commit() writes the header, VLRs
// and EVLRs and renames it onto `path`; a writer destroyed uncommitted removes it.
class LasWriter {
 public:
  // create = true: makes the temporary file (exactly one process does this); create = false:
  // opens the one another process created.
  LasWriter(std::string path, const std::string& tag, const LasHeader& header, bool create);
  ~LasWriter();
  LasWriter(const LasWriter&) = delete;
  LasWriter& operator=(const LasWriter&) = delete;

  // Writes records [first, first + count) from `records` (count * record_length bytes).
  void write_records(std::uint64_t first, std::size_t count, const std::uint8_t* records);
  // For a new file whose size is known only at the end (no EVLRs): sets the header's point
  // count (and per-return counts to "all first returns") and bounds before commit().
  void set_count_and_bounds(std::uint64_t point_count, const double min[3], const double max[3]);
  // Only the creating process: writes the header, VLRs and EVLRs, syncs and renames.
  void commit();

 private:
  std::string path_, temporary_;
  LasHeader header_;
  int fd_ = -1;
  bool owner_ = false;
  bool committed_ = false;
};

// A header for a new file without VLRs (synthetic clouds, tests).
LasHeader make_las_header(int version_minor, int point_format, std::size_t extra_bytes,
                          std::uint64_t point_count, const double scale[3], const double offset[3],
                          const double min[3], const double max[3]);

// Integer origin in record units: the centre of the header's bounding box, rounded.
void las_origin(const LasHeader& header, std::int64_t origin[3]);

// The whole file as a PointCloud: positions re-centred on las_origin() (the origin is not kept;
// the cloud is for analysis), uint16 "intensity", uchar "classification", and every typed Extra
// Bytes field by its name (glint's own as scalar_label / scalar_p_sharp / scalar_p_boundary, as
// in glint's PLY output).
PointCloud read_las(const std::string& path);

}  // namespace glint::io
