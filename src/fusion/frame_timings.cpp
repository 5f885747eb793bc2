#include "fusion/frame_timings.h"

#include <algorithm>
#include <cmath>
#include <numeric>

namespace glint::fusion {
namespace {

double quantile_of(std::vector<double> values, double q) {
  if (values.empty()) return 0;
  const auto rank = static_cast<std::size_t>(std::lround(q * double(values.size() - 1)));
  std::nth_element(values.begin(), values.begin() + rank, values.end());
  return values[rank];
}

}  // namespace

double FrameTimings::quantile_ms(const std::string& stage, double q) const {
  const auto it = samples_.find(stage);
  return it == samples_.end() ? 0.0 : quantile_of(it->second, q);
}

nlohmann::json FrameTimings::to_json() const {
  nlohmann::json out = nlohmann::json::object();
  for (const auto& [stage, values] : samples_) {
    const double total = std::accumulate(values.begin(), values.end(), 0.0);
    out[stage] = {{"count", values.size()},
                  {"total", total},
                  {"median", quantile_of(values, 0.5)},
                  {"mean", total / double(values.size())},
                  {"p90", quantile_of(values, 0.9)},
                  {"max", *std::max_element(values.begin(), values.end())}};
  }
  return out;
}

}  // namespace glint::fusion
