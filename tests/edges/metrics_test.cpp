#include "edges/metrics.h"

#include <gtest/gtest.h>

#include "core/error.h"

namespace glint::edges {
namespace {

TEST(Metrics, HandComputedConfusion) {
  // tp = 2, fp = 1, fn = 1, tn = 1.
  const BinaryScores s = score({1, 1, 0, 0, 1}, {1, 0, 0, 1, 1}, EvalTask::sharp);
  EXPECT_EQ(s.true_positives, 2u);
  EXPECT_EQ(s.false_positives, 1u);
  EXPECT_EQ(s.false_negatives, 1u);
  EXPECT_EQ(s.true_negatives, 1u);
  EXPECT_DOUBLE_EQ(s.precision, 2.0 / 3.0);
  EXPECT_DOUBLE_EQ(s.recall, 2.0 / 3.0);
  EXPECT_DOUBLE_EQ(s.f1, 2.0 / 3.0);
  EXPECT_DOUBLE_EQ(s.iou, 0.5);
  EXPECT_DOUBLE_EQ(s.accuracy, 0.6);
  EXPECT_DOUBLE_EQ(s.mcc, 1.0 / 6.0);
}

TEST(Metrics, TasksChooseThePositiveClass) {
  const std::vector<std::uint8_t> truth{0, 1, 2, 2};
  const std::vector<std::uint8_t> predicted{0, 2, 2, 1};
  EXPECT_EQ(score(predicted, truth, EvalTask::sharp).true_positives, 0u);  // boundary != sharp
  EXPECT_EQ(score(predicted, truth, EvalTask::boundary).true_positives, 1u);
  EXPECT_EQ(score(predicted, truth, EvalTask::edge).true_positives, 3u);
  EXPECT_THROW(parse_eval_task("corner"), glint::Error);
}

TEST(Metrics, DegenerateCases) {
  const BinaryScores perfect_empty = score({0, 0}, {0, 0}, EvalTask::sharp);
  EXPECT_EQ(perfect_empty.precision, 1.0);
  EXPECT_EQ(perfect_empty.mcc, 0.0);
  const BinaryScores all_wrong = score({1, 1}, {0, 0}, EvalTask::sharp);
  EXPECT_EQ(all_wrong.precision, 0.0);
  EXPECT_EQ(all_wrong.recall, 0.0);
  EXPECT_THROW(score({1}, {1, 0}, EvalTask::sharp), glint::Error);
}

TEST(Metrics, MedianAndMean) {
  std::vector<BinaryScores> files(3);
  files[0].mcc = 0.1, files[1].mcc = 0.5, files[2].mcc = 0.9;
  files[0].f1 = 0.2, files[1].f1 = 0.2, files[2].f1 = 0.8;
  const ScoreSummary summary = summarise(files);
  EXPECT_DOUBLE_EQ(summary.median.mcc, 0.5);
  EXPECT_DOUBLE_EQ(summary.mean.mcc, 0.5);
  EXPECT_DOUBLE_EQ(summary.median.f1, 0.2);
  EXPECT_DOUBLE_EQ(summary.mean.f1, 0.4);
}

TEST(Metrics, PooledScoresSumTheCounts) {
  // File 1 has no positives at all; pooled precision counts its false positive.
  const auto a = score({1, 1, 0, 0}, {1, 0, 0, 0}, EvalTask::sharp);
  const auto b = score({1, 0, 0}, {0, 0, 0}, EvalTask::sharp);
  const ScoreSummary summary = summarise({a, b});
  EXPECT_EQ(summary.pooled.true_positives, 1u);
  EXPECT_EQ(summary.pooled.false_positives, 2u);
  EXPECT_DOUBLE_EQ(summary.pooled.precision, 1.0 / 3.0);
  EXPECT_DOUBLE_EQ(summary.pooled.recall, 1.0);
  EXPECT_DOUBLE_EQ(summary.pooled.accuracy, 5.0 / 7.0);
}

}  // namespace
}  // namespace glint::edges
