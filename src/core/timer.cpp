#include "core/timer.h"

#include <algorithm>
#include <cmath>
#include <nlohmann/json.hpp>
#include <numeric>

namespace glint {
namespace {

double median_of(std::vector<double> values) {
  if (values.empty()) return 0.0;
  const std::size_t mid = values.size() / 2;
  std::nth_element(values.begin(), values.begin() + mid, values.end());
  if (values.size() % 2 == 1) return values[mid];
  const double upper = values[mid];
  return 0.5 * (upper + *std::max_element(values.begin(), values.begin() + mid));
}

// Nearest-rank q-quantile (q in [0, 1]).
double quantile_of(std::vector<double> values, double q) {
  if (values.empty()) return 0.0;
  const auto rank = static_cast<std::size_t>(std::lround(q * double(values.size() - 1)));
  std::nth_element(values.begin(), values.begin() + rank, values.end());
  return values[rank];
}

}  // namespace

void StageTimings::add(const std::string& stage, double milliseconds) {
  samples_[stage].push_back(milliseconds);
}

double StageTimings::total_ms(const std::string& stage) const {
  const auto it = samples_.find(stage);
  return it == samples_.end() ? 0.0 : std::accumulate(it->second.begin(), it->second.end(), 0.0);
}

double StageTimings::median_ms(const std::string& stage) const {
  const auto it = samples_.find(stage);
  return it == samples_.end() ? 0.0 : median_of(it->second);
}

nlohmann::json StageTimings::to_json() const {
  nlohmann::json out = nlohmann::json::object();
  for (const auto& [stage, values] : samples_) {
    const double total = std::accumulate(values.begin(), values.end(), 0.0);
    out[stage] = {{"count", values.size()},
                  {"total", total},
                  {"median", median_of(values)},
                  {"mean", total / static_cast<double>(values.size())},
                  {"p90", quantile_of(values, 0.9)},
                  {"max", *std::max_element(values.begin(), values.end())}};
  }
  return out;
}

}  // namespace glint
