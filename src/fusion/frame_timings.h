#pragma once
// Per-frame durations of the pipeline's stages, summarised for reports as
// {stage: {count, total, median, mean, p90, max}} in milliseconds.
#include <map>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

namespace glint::fusion {

class FrameTimings {
 public:
  void add(const std::string& stage, double milliseconds) {
    samples_[stage].push_back(milliseconds);
  }
  // The q-quantile (0..1, nearest rank) of a stage's samples; 0 when it has none.
  double quantile_ms(const std::string& stage, double q) const;
  double median_ms(const std::string& stage) const { return quantile_ms(stage, 0.5); }
  nlohmann::json to_json() const;

 private:
  std::map<std::string, std::vector<double>> samples_;
};

}  // namespace glint::fusion
