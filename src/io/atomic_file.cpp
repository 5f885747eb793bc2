#include "io/atomic_file.h"

#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <filesystem>
#include <system_error>
#include <utility>

#include "core/error.h"
#include "core/interrupt.h"

namespace glint::io {
namespace {

void remove_quietly(const std::string& path) {
  std::error_code ignored;
  std::filesystem::remove(path, ignored);
}

}  // namespace

AtomicFile::AtomicFile(std::string path, bool binary)
    : path_(std::move(path)), temporary_(path_ + ".tmp-" + std::to_string(::getpid())) {
  const std::filesystem::path folder = std::filesystem::path(path_).parent_path();
  std::error_code error;
  if (!folder.empty()) std::filesystem::create_directories(folder, error);
  if (error) throw Error(path_, "", "cannot create its folder: " + error.message());
  stream_.open(temporary_, binary ? std::ios::out | std::ios::binary : std::ios::out);
  if (!stream_) {
    throw Error(path_, "", std::string("cannot create the file: ") + std::strerror(errno));
  }
}

AtomicFile::~AtomicFile() {
  if (committed_) return;
  stream_.close();
  remove_quietly(temporary_);
}

void AtomicFile::commit() {
  throw_if_interrupted();  // an interrupted job leaves no output, however far it got
  stream_.flush();
  const bool written = stream_.good();
  stream_.close();  // fails when the last buffered bytes cannot be written
  if (!written || stream_.fail()) {
    remove_quietly(temporary_);
    throw Error(path_, "", "writing failed (is the disk full?)");
  }
  std::error_code error;
  std::filesystem::rename(temporary_, path_, error);
  if (error) {
    remove_quietly(temporary_);
    throw Error(path_, "", "cannot move the finished file into place: " + error.message());
  }
  committed_ = true;
}

}  // namespace glint::io
