#pragma once
// AtomicFile: writes go to a temporary file next to the target and are renamed over it on
// commit(), so a failed or interrupted write never leaves a half-written output behind.
#include <fstream>
#include <string>

namespace glint::io {

class AtomicFile {
 public:
  // Creates the folders `path` lies in when missing and opens "<path>.tmp-<pid>" for writing;
  // throws glint::Error naming `path` when it cannot.
  explicit AtomicFile(std::string path, bool binary = true);
  AtomicFile(const AtomicFile&) = delete;
  AtomicFile& operator=(const AtomicFile&) = delete;
  // Removes the temporary file unless commit() succeeded.
  ~AtomicFile();

  std::ostream& stream() { return stream_; }
  // Flushes, checks the stream and renames the temporary file onto the target; throws
  // glint::Error (and removes the temporary) on any failure, e.g. a full disk.
  void commit();

 private:
  std::string path_;
  std::string temporary_;
  std::ofstream stream_;
  bool committed_ = false;
};

}  // namespace glint::io
