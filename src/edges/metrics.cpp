#include "edges/metrics.h"

#include <algorithm>
#include <cmath>
#include <nlohmann/json.hpp>

#include "core/error.h"

namespace glint::edges {

EvalTask parse_eval_task(const std::string& name) {
  if (name == "sharp") return EvalTask::sharp;
  if (name == "boundary") return EvalTask::boundary;
  if (name == "edge") return EvalTask::edge;
  throw Error("", "--task", "unknown task '" + name + "' (sharp, boundary, edge)");
}

std::string to_string(EvalTask task) {
  switch (task) {
    case EvalTask::sharp:
      return "sharp";
    case EvalTask::boundary:
      return "boundary";
    case EvalTask::edge:
      return "edge";
  }
  return "?";
}

bool is_positive(std::uint8_t label, EvalTask task) {
  switch (task) {
    case EvalTask::sharp:
      return label == 1;
    case EvalTask::boundary:
      return label == 2;
    case EvalTask::edge:
      return label == 1 || label == 2;
  }
  return false;
}

namespace {

double ratio(double numerator, double denominator) {
  return denominator > 0 ? numerator / denominator : 0.0;
}

}  // namespace

BinaryScores score(const std::vector<std::uint8_t>& predicted,
                   const std::vector<std::uint8_t>& truth, EvalTask task) {
  if (predicted.size() != truth.size()) {
    throw Error("", "evaluation",
                "prediction has " + std::to_string(predicted.size()) +
                    " labels but ground truth has " + std::to_string(truth.size()));
  }
  BinaryScores s;
  for (std::size_t i = 0; i < truth.size(); ++i) {
    const bool p = is_positive(predicted[i], task), t = is_positive(truth[i], task);
    if (p && t)
      ++s.true_positives;
    else if (p)
      ++s.false_positives;
    else if (t)
      ++s.false_negatives;
    else
      ++s.true_negatives;
  }
  return scores_from_counts(s);
}

BinaryScores scores_from_counts(BinaryScores s) {
  const double tp = double(s.true_positives), fp = double(s.false_positives),
               tn = double(s.true_negatives), fn = double(s.false_negatives);
  if (tp + fp + fn == 0) {
    s.precision = s.recall = s.f1 = s.iou = 1.0;
  } else {
    s.precision = ratio(tp, tp + fp);
    s.recall = ratio(tp, tp + fn);
    s.f1 = ratio(2 * tp, 2 * tp + fp + fn);
    s.iou = ratio(tp, tp + fp + fn);
  }
  s.accuracy = ratio(tp + tn, tp + tn + fp + fn);
  const double denominator = (tp + fp) * (tp + fn) * (tn + fp) * (tn + fn);
  s.mcc = denominator > 0 ? (tp * tn - fp * fn) / std::sqrt(denominator) : 0.0;
  return s;
}

nlohmann::json to_json(const BinaryScores& s) {
  return {{"precision", s.precision},
          {"recall", s.recall},
          {"mcc", s.mcc},
          {"f1", s.f1},
          {"accuracy", s.accuracy},
          {"iou", s.iou},
          {"tp", s.true_positives},
          {"fp", s.false_positives},
          {"tn", s.true_negatives},
          {"fn", s.false_negatives}};
}

ScoreSummary summarise(const std::vector<BinaryScores>& per_file) {
  ScoreSummary summary;
  if (per_file.empty()) return summary;
  for (const auto& s : per_file) {
    summary.pooled.true_positives += s.true_positives;
    summary.pooled.false_positives += s.false_positives;
    summary.pooled.true_negatives += s.true_negatives;
    summary.pooled.false_negatives += s.false_negatives;
  }
  summary.pooled = scores_from_counts(summary.pooled);
  auto reduce = [&](double BinaryScores::*field) {
    std::vector<double> values;
    for (const auto& s : per_file) values.push_back(s.*field);
    std::sort(values.begin(), values.end());
    const std::size_t n = values.size();
    summary.median.*field = n % 2 ? values[n / 2] : 0.5 * (values[n / 2 - 1] + values[n / 2]);
    double total = 0;
    for (double v : values) total += v;
    summary.mean.*field = total / double(n);
  };
  for (auto field : {&BinaryScores::precision, &BinaryScores::recall, &BinaryScores::mcc,
                     &BinaryScores::f1, &BinaryScores::accuracy, &BinaryScores::iou}) {
    reduce(field);
  }
  return summary;
}

}  // namespace glint::edges
