#include "io/file_bytes.h"

#include <cerrno>
#include <cstring>
#include <filesystem>
#include <fstream>

#include "core/error.h"

namespace glint::io {

std::string read_file_bytes(const std::string& path) {
  std::error_code error;
  if (std::filesystem::is_directory(path, error)) throw Error(path, "", "is a folder, not a file");
  std::ifstream stream(path, std::ios::binary);
  if (!stream) throw Error(path, "", std::string("cannot open the file: ") + std::strerror(errno));
  std::string bytes;
  stream.seekg(0, std::ios::end);
  const std::streamoff size = stream.tellg();
  stream.seekg(0, std::ios::beg);
  if (size > 0) {
    bytes.resize(static_cast<std::size_t>(size));
    stream.read(bytes.data(), size);
  }
  if (!stream) throw Error(path, "", "read failed");
  return bytes;
}

}  // namespace glint::io
