#include "io/las.h"

#include <fcntl.h>
#include <fmt/format.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <bit>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <filesystem>

#include "core/error.h"
#include "core/interrupt.h"

namespace glint::io {
namespace {

static_assert(std::endian::native == std::endian::little,
              "LAS is little-endian; so must the host be");

// Public header sizes per minor version and the byte positions of its fields (LAS 1.4 Table 3).
constexpr std::size_t kHeaderSize12 = 227, kHeaderSize13 = 235, kHeaderSize14 = 375;
constexpr std::size_t kVlrHeaderSize = 54, kEvlrHeaderSize = 60, kExtraBytesDescriptor = 192;
constexpr std::size_t kBoundedBytes = 9;  // uchar + 2 floats
namespace at {
constexpr std::size_t version_major = 24, version_minor = 25, header_size = 94,
                      offset_to_points = 96, vlr_count = 100, point_format = 104,
                      record_length = 105, legacy_point_count = 107, scale = 131, offset = 155,
                      bounds = 179, waveform_start = 227, evlr_start = 235, evlr_count = 243,
                      point_count = 247;
}

template <class T>
T get(const std::uint8_t* bytes, std::size_t position) {
  T value;
  std::memcpy(&value, bytes + position, sizeof(T));
  return value;
}
template <class T>
void put(std::uint8_t* bytes, std::size_t position, T value) {
  std::memcpy(bytes + position, &value, sizeof(T));
}

// Copies a name into a fixed-size, zero-padded LAS character field.
void put_string(std::uint8_t* field, std::size_t size, const char* text) {
  std::memcpy(field, text, std::min(std::strlen(text), size));
}

std::string fixed_string(const std::uint8_t* bytes, std::size_t size) {
  std::size_t length = 0;
  while (length < size && bytes[length] != 0) ++length;
  return std::string(reinterpret_cast<const char*>(bytes), length);
}

std::size_t extra_type_size(int data_type, int options) {
  static constexpr std::size_t sizes[] = {0, 1, 1, 2, 2, 4, 4, 8, 8, 4, 8};
  if (data_type == 0) return static_cast<std::size_t>(options);
  if (data_type >= 1 && data_type <= 10) return sizes[data_type];
  if (data_type >= 11 && data_type <= 30) return 2 * sizes[(data_type - 11) % 10 + 1];  // arrays
  return 0;
}

void read_exact(int fd, std::uint64_t position, std::size_t size, std::uint8_t* out,
                const std::string& path, const std::string& what) {
  std::size_t done = 0;
  while (done < size) {
    const ssize_t got = ::pread(fd, out + done, size - done, static_cast<off_t>(position + done));
    if (got < 0 && errno == EINTR) continue;
    if (got <= 0) {
      throw Error(
          path, what,
          got == 0 ? fmt::format("truncated: ends inside the {} bytes at byte {}", size, position)
                   : fmt::format("read failed: {}", std::strerror(errno)));
    }
    done += static_cast<std::size_t>(got);
  }
}

void write_exact(int fd, std::uint64_t position, std::size_t size, const std::uint8_t* data,
                 const std::string& path) {
  std::size_t done = 0;
  while (done < size) {
    const ssize_t put_count =
        ::pwrite(fd, data + done, size - done, static_cast<off_t>(position + done));
    if (put_count < 0 && errno == EINTR) continue;
    if (put_count <= 0)
      throw Error(path, "", fmt::format("write failed: {}", std::strerror(errno)));
    done += static_cast<std::size_t>(put_count);
  }
}

// Parses the Extra Bytes descriptors of one VLR payload into `header.extra_fields`.
void parse_extra_bytes(const std::uint8_t* payload, std::size_t length, LasHeader& header,
                       const std::string& path) {
  if (length % kExtraBytesDescriptor != 0) {
    throw Error(path, "Extra Bytes VLR",
                fmt::format("length {} is not a multiple of the {}-byte descriptor", length,
                            kExtraBytesDescriptor));
  }
  std::size_t position = las_min_record_length(header.point_format);
  for (std::size_t d = 0; d < length / kExtraBytesDescriptor; ++d) {
    const std::uint8_t* descriptor = payload + d * kExtraBytesDescriptor;
    LasExtraField field;
    field.data_type = descriptor[2];
    field.name = fixed_string(descriptor + 4, 32);
    field.size = extra_type_size(field.data_type, descriptor[3]);
    field.offset = position;
    if (field.size == 0) {
      throw Error(path, fmt::format("Extra Bytes descriptor {} ('{}')", d, field.name),
                  fmt::format("unknown data type {}", field.data_type));
    }
    position += field.size;
    if (position > header.record_length) {
      throw Error(
          path, fmt::format("Extra Bytes descriptor {} ('{}')", d, field.name),
          fmt::format("ends at byte {} of a {}-byte point record", position, header.record_length));
    }
    header.extra_fields.push_back(std::move(field));
  }
}

void parse_vlrs(LasHeader& header, const std::string& path) {
  std::size_t position = 0;
  const std::size_t available = header.vlr_bytes.size();
  for (std::uint32_t v = 0; v < header.vlr_count; ++v) {
    if (position + kVlrHeaderSize > available) {
      throw Error(path, fmt::format("VLR {}", v),
                  fmt::format("header runs past the start of the point data (byte {}); the "
                              "file declares {} VLRs",
                              header.offset_to_points, header.vlr_count));
    }
    const std::uint8_t* vlr = header.vlr_bytes.data() + position;
    const std::string user = fixed_string(vlr + 2, 16);
    const auto record_id = get<std::uint16_t>(vlr, 18);
    const std::size_t length = get<std::uint16_t>(vlr, 20);
    if (position + kVlrHeaderSize + length > available) {
      throw Error(path, fmt::format("VLR {} ('{}' {})", v, user, record_id),
                  fmt::format("its {} bytes run past the start of the point data (byte {})", length,
                              header.offset_to_points));
    }
    if (user == "LASF_Spec" && record_id == 4) {
      parse_extra_bytes(vlr + kVlrHeaderSize, length, header, path);
    }
    position += kVlrHeaderSize + length;
  }
}

void check_evlrs(const LasHeader& header, const std::string& path) {
  std::size_t position = 0;
  for (std::uint32_t v = 0; v < header.evlr_count; ++v) {
    if (position + kEvlrHeaderSize > header.evlr_bytes.size()) {
      throw Error(path, fmt::format("EVLR {}", v), "truncated: the file ends inside its header");
    }
    const std::uint64_t length = get<std::uint64_t>(header.evlr_bytes.data() + position, 20);
    if (length > header.evlr_bytes.size() - position - kEvlrHeaderSize) {
      throw Error(path, fmt::format("EVLR {}", v),
                  fmt::format("truncated: declares {} bytes, the file holds {}", length,
                              header.evlr_bytes.size() - position - kEvlrHeaderSize));
    }
    position += kEvlrHeaderSize + length;
  }
}

}  // namespace

const LasExtraField* LasHeader::find_extra(const std::string& name) const {
  for (const LasExtraField& field : extra_fields) {
    if (field.name == name) return &field;
  }
  return nullptr;
}

std::size_t las_min_record_length(int point_format) {
  static constexpr std::size_t lengths[] = {20, 28, 26, 34, 57, 63, 30, 36, 38, 59, 67};
  return point_format >= 0 && point_format <= 10 ? lengths[point_format] : 0;
}

LasReader::LasReader(std::string path) : path_(std::move(path)) {
  std::string extension = std::filesystem::path(path_).extension().string();
  std::transform(extension.begin(), extension.end(), extension.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  const std::string laz_help =
      "LAZ (compressed LAS) is not supported; decompress it first, e.g. `laszip -i in.laz -o "
      "in.las` (LAStools) or `pdal translate in.laz in.las`";
  if (extension == ".laz") throw Error(path_, "", laz_help);
  fd_ = ::open(path_.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd_ < 0) throw Error(path_, "", fmt::format("cannot open: {}", std::strerror(errno)));
  struct stat info {};
  ::fstat(fd_, &info);
  const auto file_size = static_cast<std::uint64_t>(info.st_size);

  LasHeader& h = header_;
  std::uint8_t start[kHeaderSize14] = {};
  if (file_size < kHeaderSize12) {
    ::close(fd_);
    fd_ = -1;
    throw Error(path_, "public header",
                fmt::format("truncated: the file has {} bytes, the header alone needs {}",
                            file_size, kHeaderSize12));
  }
  try {
    read_exact(fd_, 0, std::min<std::uint64_t>(file_size, kHeaderSize14), start, path_,
               "public header");
    if (std::memcmp(start, "LASF", 4) != 0) {
      throw Error(path_, "file signature", "is not 'LASF': not a LAS file");
    }
    if (start[at::version_major] != 1 || start[at::version_minor] > 4) {
      throw Error(path_, "version",
                  fmt::format("{}.{} is not supported (1.2 to 1.4)", start[at::version_major],
                              start[at::version_minor]));
    }
    h.version_minor = start[at::version_minor];
    const std::size_t needed = h.version_minor >= 4   ? kHeaderSize14
                               : h.version_minor == 3 ? kHeaderSize13
                                                      : kHeaderSize12;
    const std::size_t header_size = get<std::uint16_t>(start, at::header_size);
    if (header_size < needed || header_size > file_size) {
      throw Error(path_, "header size",
                  fmt::format("{} bytes: LAS 1.{} needs at least {} and the file has {}",
                              header_size, h.version_minor, needed, file_size));
    }
    const int format_byte = start[at::point_format];
    if (format_byte & 0xC0) throw Error(path_, "point data format", laz_help);
    h.point_format = format_byte;
    if (h.point_format > 10) {
      throw Error(path_, "point data format",
                  fmt::format("{} is not a LAS point format (0 to 10)", h.point_format));
    }
    h.record_length = get<std::uint16_t>(start, at::record_length);
    if (h.record_length < las_min_record_length(h.point_format)) {
      throw Error(path_, "point data record length",
                  fmt::format("{} bytes is shorter than format {}'s {}", h.record_length,
                              h.point_format, las_min_record_length(h.point_format)));
    }
    h.offset_to_points = get<std::uint32_t>(start, at::offset_to_points);
    if (h.offset_to_points < header_size || h.offset_to_points > file_size) {
      throw Error(path_, "offset to point data",
                  fmt::format("{} lies outside the file's {} bytes after the {}-byte header",
                              h.offset_to_points, file_size, header_size));
    }
    h.vlr_count = get<std::uint32_t>(start, at::vlr_count);
    h.point_count = get<std::uint32_t>(start, at::legacy_point_count);
    if (h.version_minor >= 4) {
      const auto count = get<std::uint64_t>(start, at::point_count);
      if (count != 0 || h.point_format >= 6) h.point_count = count;
      h.evlr_start = get<std::uint64_t>(start, at::evlr_start);
      h.evlr_count = get<std::uint32_t>(start, at::evlr_count);
    }
    static const char* const axis_names[] = {"x", "y", "z"};
    for (int a = 0; a < 3; ++a) {
      h.scale[a] = get<double>(start, at::scale + 8 * a);
      h.offset[a] = get<double>(start, at::offset + 8 * a);
      h.max[a] = get<double>(start, at::bounds + 16 * a);
      h.min[a] = get<double>(start, at::bounds + 16 * a + 8);
      if (!(h.scale[a] > 0) || !std::isfinite(h.scale[a]) || !std::isfinite(h.offset[a])) {
        throw Error(path_, fmt::format("{} scale factor / offset", axis_names[a]),
                    fmt::format("{} / {}: the scale must be positive and both finite", h.scale[a],
                                h.offset[a]));
      }
    }
    h.header_bytes.resize(header_size);
    read_exact(fd_, 0, header_size, h.header_bytes.data(), path_, "public header");
    h.vlr_bytes.resize(h.offset_to_points - header_size);
    read_exact(fd_, header_size, h.vlr_bytes.size(), h.vlr_bytes.data(), path_, "VLRs");
    parse_vlrs(h, path_);

    const std::uint64_t points_end = h.offset_to_points + h.point_count * h.record_length;
    if (h.point_count > (file_size - h.offset_to_points) / h.record_length) {
      throw Error(path_, "point data",
                  fmt::format("truncated: the header declares {} points of {} bytes, the file "
                              "holds {}",
                              h.point_count, h.record_length,
                              (file_size - h.offset_to_points) / h.record_length));
    }
    if (h.evlr_count > 0) {
      if (h.evlr_start < points_end || h.evlr_start > file_size) {
        throw Error(path_, "start of first EVLR",
                    fmt::format("byte {} is not between the end of the point data ({}) and "
                                "the end of the file ({})",
                                h.evlr_start, points_end, file_size));
      }
      h.evlr_bytes.resize(file_size - h.evlr_start);
      read_exact(fd_, h.evlr_start, h.evlr_bytes.size(), h.evlr_bytes.data(), path_, "EVLRs");
      check_evlrs(h, path_);
    }
  } catch (...) {
    ::close(fd_);
    fd_ = -1;
    throw;
  }
}

LasReader::~LasReader() {
  if (fd_ >= 0) ::close(fd_);
}

void LasReader::read_records(std::uint64_t first, std::size_t count, std::uint8_t* records) const {
  read_exact(fd_, header_.offset_to_points + first * header_.record_length,
             count * header_.record_length, records, path_, fmt::format("point {}", first));
}

void las_record_xyz(const std::uint8_t* record, std::int32_t xyz[3]) {
  std::memcpy(xyz, record, 3 * sizeof(std::int32_t));
}

LasHeader las_header_with_bounded_fields(const LasHeader& input, const std::string& input_path,
                                         LasBoundedFields& fields) {
  const LasExtraField* label = input.find_extra("bounded_label");
  const LasExtraField* p_sharp = input.find_extra("p_sharp");
  const LasExtraField* p_boundary = input.find_extra("p_boundary");
  if (label || p_sharp || p_boundary) {
    // Re-classifying a glint output: overwrite its values, keep the layout.
    if (!label || !p_sharp || !p_boundary || label->data_type != 1 || p_sharp->data_type != 9 ||
        p_boundary->data_type != 9) {
      throw Error(input_path, "Extra Bytes VLR",
                  "has some of bounded_label (uchar), p_sharp, p_boundary (float) but not all "
                  "three with these types; glint would not know where to write its results");
    }
    fields = {label->offset, p_sharp->offset, p_boundary->offset, false};
    return input;
  }

  LasHeader output = input;
  fields.label_offset = input.record_length;
  fields.p_sharp_offset = input.record_length + 1;
  fields.p_boundary_offset = input.record_length + 5;
  fields.appended = true;
  output.record_length = input.record_length + kBoundedBytes;
  if (output.record_length > 0xFFFF) {
    throw Error(input_path, "point data record length",
                "no room for 9 more bytes in a LAS record (65535 at most)");
  }
  // Bytes the input records carry beyond their format and its own descriptors are
  // undocumented extra bytes; describe them (type 0) so that ours land at the right offset.
  std::size_t described = las_min_record_length(input.point_format);
  for (const LasExtraField& field : input.extra_fields) described += field.size;
  const std::size_t undocumented = input.record_length - described;

  std::vector<std::uint8_t> descriptors;
  auto add_descriptor = [&](const char* name, int data_type, int options, const char* description) {
    std::uint8_t descriptor[kExtraBytesDescriptor] = {};
    descriptor[2] = static_cast<std::uint8_t>(data_type);
    descriptor[3] = static_cast<std::uint8_t>(options);
    put_string(descriptor + 4, 32, name);
    put_string(descriptor + 160, 32, description);
    descriptors.insert(descriptors.end(), descriptor, descriptor + kExtraBytesDescriptor);
  };
  if (undocumented > 0) {
    if (undocumented > 255) {
      throw Error(input_path, "point data record length",
                  fmt::format("{} undescribed extra bytes per record (255 at most)", undocumented));
    }
    add_descriptor("undescribed", 0, static_cast<int>(undocumented), "input's own bytes");
  }
  add_descriptor("bounded_label", 1, 0, "glint: 0 none 1 sharp 2 boundary");
  add_descriptor("p_sharp", 9, 0, "glint: sharp-edge probability");
  add_descriptor("p_boundary", 9, 0, "glint: boundary probability");

  // Append the descriptors to the Extra Bytes VLR, or add one after the others.
  std::vector<std::uint8_t> vlrs;
  std::size_t position = 0;
  bool extended = false;
  for (std::uint32_t v = 0; v < input.vlr_count; ++v) {
    const std::uint8_t* vlr = input.vlr_bytes.data() + position;
    const std::size_t length = get<std::uint16_t>(vlr, 20);
    const std::size_t size = kVlrHeaderSize + length;
    vlrs.insert(vlrs.end(), vlr, vlr + size);
    if (fixed_string(vlr + 2, 16) == "LASF_Spec" && get<std::uint16_t>(vlr, 18) == 4) {
      const std::size_t new_length = length + descriptors.size();
      if (new_length > 0xFFFF) {
        throw Error(input_path, "Extra Bytes VLR", "no room for three more descriptors");
      }
      put<std::uint16_t>(vlrs.data() + vlrs.size() - size, 20,
                         static_cast<std::uint16_t>(new_length));
      vlrs.insert(vlrs.end(), descriptors.begin(), descriptors.end());
      extended = true;
    }
    position += size;
  }
  if (!extended) {
    std::uint8_t vlr[kVlrHeaderSize] = {};
    put_string(vlr + 2, 16, "LASF_Spec");
    put<std::uint16_t>(vlr, 18, 4);
    put<std::uint16_t>(vlr, 20, static_cast<std::uint16_t>(descriptors.size()));
    put_string(vlr + 22, 32, "Extra Bytes");
    vlrs.insert(vlrs.end(), vlr, vlr + kVlrHeaderSize);
    vlrs.insert(vlrs.end(), descriptors.begin(), descriptors.end());
    ++output.vlr_count;
  }
  // Whatever followed the VLRs before the point data (padding, user bytes) stays.
  vlrs.insert(vlrs.end(), input.vlr_bytes.begin() + static_cast<std::ptrdiff_t>(position),
              input.vlr_bytes.end());
  output.vlr_bytes = std::move(vlrs);
  output.offset_to_points = output.header_bytes.size() + output.vlr_bytes.size();
  if (output.offset_to_points > 0xFFFFFFFFull) {
    throw Error(input_path, "VLRs", "too long for a LAS header's 32-bit point data offset");
  }
  const std::uint64_t input_end = input.offset_to_points + input.point_count * input.record_length;
  const std::uint64_t output_end =
      output.offset_to_points + output.point_count * output.record_length;
  if (output.evlr_count > 0) output.evlr_start = output_end;
  if (output.version_minor >= 3) {
    // Waveform data stored after the point records (in an EVLR) moves with them.
    const auto waveform = get<std::uint64_t>(output.header_bytes.data(), at::waveform_start);
    if (waveform != 0 && waveform >= input_end) {
      put<std::uint64_t>(output.header_bytes.data(), at::waveform_start,
                         waveform - input_end + output_end);
    }
  }
  // Only our descriptors change the parsed view; keep it consistent for the caller.
  output.extra_fields.clear();
  parse_vlrs(output, input_path);
  return output;
}

void las_set_bounded_fields(std::uint8_t* record, const LasBoundedFields& fields,
                            std::uint8_t label, float p_sharp, float p_boundary) {
  record[fields.label_offset] = label;
  put(record, fields.p_sharp_offset, p_sharp);
  put(record, fields.p_boundary_offset, p_boundary);
}

namespace {

// The public header with this header's numbers written into it; the input's other bytes
// (system identifier, GUID, dates, per-return counts ...) are kept.
std::vector<std::uint8_t> serialise_header(const LasHeader& h) {
  std::vector<std::uint8_t> bytes = h.header_bytes;
  put<std::uint32_t>(bytes.data(), at::offset_to_points,
                     static_cast<std::uint32_t>(h.offset_to_points));
  put<std::uint32_t>(bytes.data(), at::vlr_count, h.vlr_count);
  put<std::uint16_t>(bytes.data(), at::record_length, static_cast<std::uint16_t>(h.record_length));
  if (h.version_minor >= 4) {
    put<std::uint64_t>(bytes.data(), at::evlr_start, h.evlr_count > 0 ? h.evlr_start : 0);
  }
  return bytes;
}

}  // namespace

LasWriter::LasWriter(std::string path, const std::string& tag, const LasHeader& header, bool create)
    : path_(std::move(path)), temporary_(path_ + ".tmp-" + tag), header_(header), owner_(create) {
  if (create) {
    const std::filesystem::path parent = std::filesystem::path(path_).parent_path();
    std::error_code ignored;
    if (!parent.empty()) std::filesystem::create_directories(parent, ignored);
  }
  fd_ = ::open(temporary_.c_str(),
               create ? (O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC) : (O_WRONLY | O_CLOEXEC), 0644);
  if (fd_ < 0) throw Error(path_, "", fmt::format("cannot write: {}", std::strerror(errno)));
  if (create) {
    const std::uint64_t points_end =
        header_.offset_to_points + header_.point_count * header_.record_length;
    if (::ftruncate(fd_, static_cast<off_t>(points_end)) != 0) {
      throw Error(path_, "", fmt::format("cannot size the output: {}", std::strerror(errno)));
    }
  }
}

void LasWriter::set_count_and_bounds(std::uint64_t point_count, const double min[3],
                                     const double max[3]) {
  header_.point_count = point_count;
  std::uint8_t* b = header_.header_bytes.data();
  const std::uint32_t legacy =
      header_.point_format < 6 && point_count <= 0xFFFFFFFFull ? std::uint32_t(point_count) : 0;
  put<std::uint32_t>(b, at::legacy_point_count, legacy);
  put<std::uint32_t>(b, at::legacy_point_count + 4, legacy);  // first returns
  if (header_.version_minor >= 4) {
    put<std::uint64_t>(b, at::point_count, point_count);
    put<std::uint64_t>(b, at::point_count + 8, point_count);
  }
  for (int a = 0; a < 3; ++a) {
    header_.min[a] = min[a];
    header_.max[a] = max[a];
    put<double>(b, at::bounds + 16 * a, max[a]);
    put<double>(b, at::bounds + 16 * a + 8, min[a]);
  }
}

LasWriter::~LasWriter() {
  if (fd_ >= 0) ::close(fd_);
  if (owner_ && !committed_) ::unlink(temporary_.c_str());
}

void LasWriter::write_records(std::uint64_t first, std::size_t count, const std::uint8_t* records) {
  write_exact(fd_, header_.offset_to_points + first * header_.record_length,
              count * header_.record_length, records, path_);
}

void LasWriter::commit() {
  const std::uint64_t points_end =
      header_.offset_to_points + header_.point_count * header_.record_length;
  const std::vector<std::uint8_t> bytes = serialise_header(header_);
  write_exact(fd_, 0, bytes.size(), bytes.data(), path_);
  write_exact(fd_, bytes.size(), header_.vlr_bytes.size(), header_.vlr_bytes.data(), path_);
  write_exact(fd_, points_end, header_.evlr_bytes.size(), header_.evlr_bytes.data(), path_);
  if (::fsync(fd_) != 0 || ::close(fd_) != 0) {
    fd_ = -1;
    throw Error(path_, "", fmt::format("write failed: {}", std::strerror(errno)));
  }
  fd_ = -1;
  throw_if_interrupted();  // an interrupted job leaves no output (the destructor unlinks it)
  if (std::rename(temporary_.c_str(), path_.c_str()) != 0) {
    throw Error(path_, "",
                fmt::format("cannot rename the finished file: {}", std::strerror(errno)));
  }
  committed_ = true;
}

LasHeader make_las_header(int version_minor, int point_format, std::size_t extra_bytes,
                          std::uint64_t point_count, const double scale[3], const double offset[3],
                          const double min[3], const double max[3]) {
  LasHeader h;
  h.version_minor = version_minor;
  h.point_format = point_format;
  h.record_length = las_min_record_length(point_format) + extra_bytes;
  h.point_count = point_count;
  const std::size_t size = version_minor >= 4   ? kHeaderSize14
                           : version_minor == 3 ? kHeaderSize13
                                                : kHeaderSize12;
  h.header_bytes.assign(size, 0);
  std::uint8_t* b = h.header_bytes.data();
  std::memcpy(b, "LASF", 4);
  b[at::version_major] = 1;
  b[at::version_minor] = static_cast<std::uint8_t>(version_minor);
  put_string(b + 26, 32, "glint");
  put_string(b + 58, 32, "glint");
  put<std::uint16_t>(b, at::header_size, static_cast<std::uint16_t>(size));
  b[at::point_format] = static_cast<std::uint8_t>(point_format);
  if (point_format < 6 && point_count <= 0xFFFFFFFFull) {
    put<std::uint32_t>(b, at::legacy_point_count, static_cast<std::uint32_t>(point_count));
  }
  if (version_minor >= 4) put<std::uint64_t>(b, at::point_count, point_count);
  for (int a = 0; a < 3; ++a) {
    h.scale[a] = scale[a];
    h.offset[a] = offset[a];
    h.min[a] = min[a];
    h.max[a] = max[a];
    put<double>(b, at::scale + 8 * a, scale[a]);
    put<double>(b, at::offset + 8 * a, offset[a]);
    put<double>(b, at::bounds + 16 * a, max[a]);
    put<double>(b, at::bounds + 16 * a + 8, min[a]);
  }
  h.offset_to_points = size;
  return h;
}

void las_origin(const LasHeader& header, std::int64_t origin[3]) {
  for (int a = 0; a < 3; ++a) {
    // Bounds are stored as X * scale + offset; back in record units they are integers up to
    // rounding, so the rounded midpoint does not depend on the offset.
    const double low = std::round((header.min[a] - header.offset[a]) / header.scale[a]);
    const double high = std::round((header.max[a] - header.offset[a]) / header.scale[a]);
    const double middle = std::isfinite(low + high) ? std::clamp((low + high) / 2, -4e18, 4e18) : 0;
    origin[a] = static_cast<std::int64_t>(std::floor(middle));
  }
}

PointCloud read_las(const std::string& path) {
  const LasReader reader(path);
  const LasHeader& h = reader.header();
  std::int64_t origin[3];
  las_origin(h, origin);
  const std::size_t n = h.point_count;
  PointCloud cloud;
  cloud.resize(n);
  std::vector<std::uint16_t> intensity(n);
  std::vector<std::uint8_t> classification(n);
  std::vector<AttributeColumn> extras;
  for (const LasExtraField& field : h.extra_fields) {
    switch (field.data_type) {
      case 1:
        extras.emplace_back(std::vector<std::uint8_t>(n));
        break;
      case 2:
        extras.emplace_back(std::vector<std::int8_t>(n));
        break;
      case 3:
        extras.emplace_back(std::vector<std::uint16_t>(n));
        break;
      case 4:
        extras.emplace_back(std::vector<std::int16_t>(n));
        break;
      case 5:
        extras.emplace_back(std::vector<std::uint32_t>(n));
        break;
      case 6:
        extras.emplace_back(std::vector<std::int32_t>(n));
        break;
      case 9:
        extras.emplace_back(std::vector<float>(n));
        break;
      case 7:
      case 8:
      case 10:
        extras.emplace_back(std::vector<double>(n));
        break;
      default:
        extras.emplace_back(std::vector<std::uint8_t>());
        break;  // arrays, opaque
    }
  }
  const std::size_t classification_at = h.point_format >= 6 ? 16 : 15;
  // About 4 MiB of records per read, and never more than the file holds: a record may be up to
  // 65535 bytes long, and 2^16 of them made a 4 GiB buffer for a few-kilobyte file.
  const std::size_t chunk = std::max<std::size_t>(1, (std::size_t(1) << 22) / h.record_length);
  std::vector<std::uint8_t> buffer(std::min(chunk, n) * h.record_length);
  for (std::size_t first = 0; first < n; first += chunk) {
    const std::size_t count = std::min(chunk, n - first);
    reader.read_records(first, count, buffer.data());
    for (std::size_t j = 0; j < count; ++j) {
      const std::uint8_t* record = buffer.data() + j * h.record_length;
      const std::size_t i = first + j;
      std::int32_t xyz[3];
      las_record_xyz(record, xyz);
      cloud.x[i] = static_cast<float>(double(xyz[0] - origin[0]) * h.scale[0]);
      cloud.y[i] = static_cast<float>(double(xyz[1] - origin[1]) * h.scale[1]);
      cloud.z[i] = static_cast<float>(double(xyz[2] - origin[2]) * h.scale[2]);
      intensity[i] = get<std::uint16_t>(record, 12);
      classification[i] = h.point_format >= 6 ? record[classification_at]
                                              : static_cast<std::uint8_t>(record[15] & 0x1F);
      for (std::size_t e = 0; e < extras.size(); ++e) {
        const LasExtraField& field = h.extra_fields[e];
        std::visit(
            [&](auto& column) {
              using T = typename std::decay_t<decltype(column)>::value_type;
              if (column.empty()) return;
              if (field.data_type == 7) {
                column[i] = static_cast<T>(get<std::uint64_t>(record, field.offset));
              } else if (field.data_type == 8) {
                column[i] = static_cast<T>(get<std::int64_t>(record, field.offset));
              } else {
                column[i] = get<T>(record, field.offset);
              }
            },
            extras[e]);
      }
    }
  }
  cloud.set("intensity", std::move(intensity));
  cloud.set("classification", std::move(classification));
  for (std::size_t e = 0; e < extras.size(); ++e) {
    if (column_size(extras[e]) != n) continue;
    const std::string& name = h.extra_fields[e].name;
    const bool ours = name == "bounded_label" || name == "p_sharp" || name == "p_boundary";
    cloud.set(ours ? (name == "bounded_label" ? "scalar_label" : "scalar_" + name) : name,
              std::move(extras[e]));
  }
  return cloud;
}

}  // namespace glint::io
