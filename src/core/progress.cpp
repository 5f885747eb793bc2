#include "core/progress.h"

#include <fmt/format.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "core/interrupt.h"

namespace glint {
namespace {
std::atomic<bool> quiet_flag{false};

// m:ss, or h:mm:ss from an hour on.
std::string clock_text(double seconds) {
  const long total = std::lround(std::max(0.0, seconds));
  if (total >= 3600)
    return fmt::format("{}:{:02}:{:02}", total / 3600, total / 60 % 60, total % 60);
  return fmt::format("{}:{:02}", total / 60, total % 60);
}
}  // namespace

std::string progress_line(const std::string& label, std::size_t done, std::size_t total,
                          double elapsed_s) {
  constexpr int width = 30;
  const std::size_t shown = std::min(done, total);
  const double fraction = total == 0 ? 1.0 : double(shown) / double(total);
  const int filled = static_cast<int>(fraction * width);
  std::string line = fmt::format("{} [{}{}] {:5.1f}% ({}/{}", label, std::string(filled, '#'),
                                 std::string(width - filled, ' '), 100.0 * fraction, shown, total);
  if (shown > 0 && elapsed_s > 0) {
    const double rate = double(shown) / elapsed_s;
    line += rate >= 1 ? fmt::format(", {:.1f}/s", rate) : fmt::format(", {:.1f} s each", 1 / rate);
    line += shown < total
                ? fmt::format(", {} left",
                              clock_text(elapsed_s * double(total - shown) / double(shown)))
                : fmt::format(", {}", clock_text(elapsed_s));
  }
  return line + ")";
}

void set_quiet(bool quiet) { quiet_flag = quiet; }
bool is_quiet() { return quiet_flag; }

ProgressBar::ProgressBar(std::string label, std::size_t total)
    : label_(std::move(label)), total_(total), enabled_(!is_quiet() && isatty(STDERR_FILENO)) {}

ProgressBar::~ProgressBar() { finish(); }

void ProgressBar::advance(std::size_t steps) {
  throw_if_interrupted();  // a step of a long job: where Ctrl-C is noticed
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
  const double elapsed_s =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
  // Padded: a shorter line (the rate's digits) must cover the one before it.
  std::fprintf(stderr, "\r%-78s", progress_line(label_, done, total_, elapsed_s).c_str());
  std::fflush(stderr);
}

void ProgressBar::finish() {
  if (!enabled_ || finished_) return;
  finished_ = true;
  draw(total_);
  std::fprintf(stderr, "\n");
}

}  // namespace glint
