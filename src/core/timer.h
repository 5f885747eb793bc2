#pragma once
// Wall-clock stopwatch and named per-stage timing statistics for reports.
#include <chrono>
#include <map>
#include <nlohmann/json_fwd.hpp>
#include <string>
#include <vector>

namespace glint {

class Stopwatch {
 public:
  Stopwatch() : start_(std::chrono::steady_clock::now()) {}
  void restart() { start_ = std::chrono::steady_clock::now(); }
  double elapsed_ms() const {
    return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start_)
        .count();
  }
  double elapsed_s() const { return elapsed_ms() / 1000.0; }

 private:
  std::chrono::steady_clock::time_point start_;
};

// Collects durations per stage name; report as JSON
// {stage: {count, total, median, mean, p90 (nearest rank), max}} in milliseconds.
class StageTimings {
 public:
  void add(const std::string& stage, double milliseconds);
  double total_ms(const std::string& stage) const;
  double median_ms(const std::string& stage) const;
  nlohmann::json to_json() const;

 private:
  std::map<std::string, std::vector<double>> samples_;
};

// Times the enclosing scope into a StageTimings entry.
class ScopedStage {
 public:
  ScopedStage(StageTimings& timings, std::string stage)
      : timings_(timings), stage_(std::move(stage)) {}
  ~ScopedStage() { timings_.add(stage_, watch_.elapsed_ms()); }
  ScopedStage(const ScopedStage&) = delete;
  ScopedStage& operator=(const ScopedStage&) = delete;

 private:
  StageTimings& timings_;
  std::string stage_;
  Stopwatch watch_;
};

}  // namespace glint
