#pragma once
// A progress bar on stderr for long jobs. Silent when stderr is not a terminal or when
// set_quiet(true) was called (the CLI's --quiet). Safe to advance from many threads.
#include <atomic>
#include <cstddef>
#include <mutex>
#include <string>

namespace glint {

void set_quiet(bool quiet);
bool is_quiet();

class ProgressBar {
 public:
  ProgressBar(std::string label, std::size_t total);
  ~ProgressBar();
  ProgressBar(const ProgressBar&) = delete;
  ProgressBar& operator=(const ProgressBar&) = delete;

  void advance(std::size_t steps = 1);
  void finish();

 private:
  void draw(std::size_t done);

  std::string label_;
  std::size_t total_;
  std::atomic<std::size_t> done_{0};
  std::atomic<int> last_permille_{-1};
  bool enabled_;
  bool finished_ = false;
  std::mutex draw_mutex_;
};

}  // namespace glint
