#include "core/progress.h"

#include <unistd.h>

#include <cstdio>

namespace glint {
namespace {
std::atomic<bool> quiet_flag{false};
}

void set_quiet(bool quiet) { quiet_flag = quiet; }
bool is_quiet() { return quiet_flag; }

ProgressBar::ProgressBar(std::string label, std::size_t total)
    : label_(std::move(label)), total_(total), enabled_(!is_quiet() && isatty(STDERR_FILENO)) {}

ProgressBar::~ProgressBar() { finish(); }

void ProgressBar::advance(std::size_t steps) {
  if (!enabled_) return;
  const std::size_t done = done_.fetch_add(steps) + steps;
  const int permille =
      total_ == 0 ? 1000 : static_cast<int>(1000 * std::min(done, total_) / total_);
  // Redraw only when the shown value changes, so hot loops do not flood the terminal.
  int last = last_permille_.load();
  if (permille / 5 == last / 5 && last >= 0) return;
  if (!last_permille_.compare_exchange_strong(last, permille)) return;
  draw(done);
}

void ProgressBar::draw(std::size_t done) {
  std::lock_guard<std::mutex> lock(draw_mutex_);
  constexpr int width = 30;
  const double fraction = total_ == 0 ? 1.0 : std::min(1.0, double(done) / double(total_));
  const int filled = static_cast<int>(fraction * width);
  std::fprintf(stderr, "\r%s [%.*s%*s] %5.1f%% (%zu/%zu)", label_.c_str(), filled,
               "##############################", width - filled, "", 100.0 * fraction,
               std::min(done, total_), total_);
  std::fflush(stderr);
}

void ProgressBar::finish() {
  if (!enabled_ || finished_) return;
  finished_ = true;
  draw(total_);
  std::fprintf(stderr, "\n");
}

}  // namespace glint
