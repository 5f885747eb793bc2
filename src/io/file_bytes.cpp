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
  std::ifstream stream(path, std::ios::binary | std::ios::ate);
  if (!stream) throw Error(path, "", std::string("cannot open the file: ") + std::strerror(errno));
  const std::streamoff size = stream.tellg();
  if (size < 0) throw Error(path, "", "cannot tell the file's size (not a regular file?)");
  std::string bytes(static_cast<std::size_t>(size), '\0');
  stream.seekg(0);
  if (!stream.read(bytes.data(), size)) throw Error(path, "", "reading the file failed");
  return bytes;
}

}  // namespace glint::io
