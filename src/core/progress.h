#pragma once
// A progress bar on stderr for long jobs. Silent when stderr is not a terminal or when
// set_quiet(true) was called (the CLI's --quiet). Safe to advance from many threads.
#include <atomic>
#include <chrono>
#include <cstddef>
#include <mutex>
#include <string>

namespace glint {

void set_quiet(bool quiet);
bool is_quiet();

// The bar's line for `done` of `total` items after `elapsed_s` seconds: the bar, the count, the
// rate and the time left (once all are done, the time taken), e.g.
//   "fuse [#########                     ]  30.0% (15/50, 4.2/s, 0:08 left)".
std::string progress_line(const std::string& label, std::size_t done, std::size_t total,
                          double elapsed_s);

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
  std::chrono::steady_clock::time_point start_ = std::chrono::steady_clock::now();
  std::atomic<std::size_t> done_{0};
  std::atomic<int> last_permille_{-1};
  bool enabled_;
  bool finished_ = false;
  std::mutex draw_mutex_;
};

}  // namespace glint
