#include "io/npy.h"

#include <fmt/format.h>

#include <charconv>
#include <cstdint>
#include <cstring>
#include <regex>
#include <sstream>

#include "core/error.h"
#include "io/atomic_file.h"
#include "io/file_bytes.h"

namespace glint::io {

void write_npy(const std::string& path, const std::vector<std::size_t>& shape,
               const float* values) {
  std::ostringstream dict;
  dict << "{'descr': '<f4', 'fortran_order': False, 'shape': (";
  std::size_t count = 1;
  for (std::size_t extent : shape) {
    dict << extent << ", ";
    count *= extent;
  }
  dict << "), }";
  std::string header = dict.str();
  // Magic, version, length and header pad to a multiple of 64 bytes, ending in '\n'.
  const std::size_t unpadded = 10 + header.size() + 1;
  header.append((64 - unpadded % 64) % 64, ' ');
  header += '\n';
  AtomicFile file(path);
  std::ostream& out = file.stream();
  out.write("\x93NUMPY\x01\x00", 8);
  const auto length = static_cast<std::uint16_t>(header.size());
  const char length_bytes[2] = {char(length & 0xff), char(length >> 8)};
  out.write(length_bytes, 2);
  out << header;
  out.write(reinterpret_cast<const char*>(values), std::streamsize(count * sizeof(float)));
  file.commit();
}

NpyArray read_npy(const std::string& path) {
  const std::string bytes = read_file_bytes(path);
  if (bytes.size() < 10 || bytes.compare(0, 6, "\x93NUMPY") != 0)
    throw Error(path, "", "not a NumPy .npy file");
  const int major = static_cast<unsigned char>(bytes[6]);
  const std::size_t length_size = major == 1 ? 2 : 4;
  if (major < 1 || major > 3 || bytes.size() < 8 + length_size)
    throw Error(path, "header", "unsupported .npy version " + std::to_string(major));
  std::size_t header_length = 0;
  for (std::size_t i = 0; i < length_size; ++i)
    header_length |= std::size_t(static_cast<unsigned char>(bytes[8 + i])) << (8 * i);
  // NumPy's own reader refuses longer headers (numpy.lib.format, max_header_size); the bound
  // also keeps std::regex's recursive matching below off deep stacks.
  constexpr std::size_t kMaxHeaderLength = 10000;
  if (header_length > kMaxHeaderLength)
    throw Error(path, "header",
                fmt::format("the header is {} bytes long, more than NumPy's limit of {}",
                            header_length, kMaxHeaderLength));
  const std::size_t data_start = 8 + length_size + header_length;
  if (data_start > bytes.size()) throw Error(path, "header", "truncated header");
  const std::string header = bytes.substr(8 + length_size, header_length);

  // Compiled once: compiling them costs more than reading a small array.
  static const std::regex descr_field("'descr':\\s*'([<>|=]?[a-z]\\d+)'");
  static const std::regex fortran_field("'fortran_order':\\s*True");
  static const std::regex shape_field("'shape':\\s*\\(([^)]*)\\)");
  static const std::regex extent_digits("\\d+");

  std::smatch match;
  if (!std::regex_search(header, match, descr_field))
    throw Error(path, "header", "no dtype ('descr')");
  const std::string descr = match[1];
  const bool is_f4 = descr == "<f4" || descr == "f4";
  const bool is_f8 = descr == "<f8" || descr == "f8";
  if (!is_f4 && !is_f8)
    throw Error(path, "header", "dtype " + descr + " is not supported (float32 or float64)");
  if (std::regex_search(header, fortran_field))
    throw Error(path, "header", "Fortran-order arrays are not supported (save with C order)");
  if (!std::regex_search(header, match, shape_field)) throw Error(path, "header", "no shape");

  NpyArray array;
  std::size_t count = 1;
  const std::string dims = match[1];
  for (auto it = std::sregex_iterator(dims.begin(), dims.end(), extent_digits);
       it != std::sregex_iterator(); ++it) {
    const char* digits = dims.data() + it->position();
    std::size_t extent = 0;
    const auto parsed = std::from_chars(digits, digits + it->length(), extent);
    if (parsed.ec != std::errc() || (extent != 0 && count > (std::size_t(1) << 40) / extent))
      throw Error(path, "header", "shape is implausibly large");
    array.shape.push_back(extent);
    count *= extent;
  }
  const std::size_t element = is_f4 ? 4 : 8;
  if (bytes.size() - data_start < count * element)
    throw Error(path, "",
                "truncated: the shape needs " + std::to_string(count * element) +
                    " data bytes, the file has " + std::to_string(bytes.size() - data_start));
  array.values.resize(count);
  const char* data = bytes.data() + data_start;
  if (count == 0) return array;  // a zero extent: no values (and no buffer to copy into)
  if (is_f4) {
    std::memcpy(array.values.data(), data, count * 4);
  } else {
    for (std::size_t i = 0; i < count; ++i) {
      double v;
      std::memcpy(&v, data + i * 8, 8);
      array.values[i] = static_cast<float>(v);
    }
  }
  return array;
}

}  // namespace glint::io
