#include "io/atomic_file.h"

#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <filesystem>
#include <system_error>

#include "core/error.h"

namespace glint::io {

AtomicFile::AtomicFile(std::string path, bool binary)
    : path_(std::move(path)), temporary_(path_ + ".tmp-" + std::to_string(::getpid())) {
  stream_.open(temporary_, binary ? std::ios::out | std::ios::binary | std::ios::trunc
                                  : std::ios::out | std::ios::trunc);
  if (!stream_) throw Error(path_, "", std::string("cannot create the file: ") + std::strerror(errno));
}

AtomicFile::~AtomicFile() {
  if (committed_) return;
  stream_.close();
  std::error_code ignored;
  std::filesystem::remove(temporary_, ignored);
}

void AtomicFile::commit() {
  stream_.flush();
  const bool written = static_cast<bool>(stream_);
  stream_.close();
  std::error_code error;
  if (written && !stream_.fail()) std::filesystem::rename(temporary_, path_, error);
  if (!written || stream_.fail() || error) {
    std::error_code ignored;
    std::filesystem::remove(temporary_, ignored);
    throw Error(path_, "", error ? "cannot rename the finished file into place: " + error.message()
                                 : std::string("write failed (disk full?)"));
  }
  committed_ = true;
}

}  // namespace glint::io
