// Table 1 metrics on hand-made maps: exact estimates, a known constant error, tiny objects.
#include "reflectance/material_evaluation.h"

#include <gtest/gtest.h>

#include <cmath>

#include "denoise/metrics.h"

namespace glint::reflectance {
namespace {

constexpr int kWidth = 40, kHeight = 30;

// Object 1 on the left half, object 2 on the right half; constant materials per object.
GroundTruthMaps truth() {
  GroundTruthMaps t;
  t.kd = ImageF(kWidth, kHeight, 3, 0.4f);
  t.ks = ImageF(kWidth, kHeight, 3, 0.1f);
  t.alpha = ImageF(kWidth, kHeight, 1, 0.2f);
  t.segment = Image<std::int32_t>(kWidth, kHeight, 1);
  for (int y = 0; y < kHeight; ++y)
    for (int x = 0; x < kWidth; ++x) t.segment.at(x, y, 0) = x < kWidth / 2 ? 1 : 2;
  return t;
}

MaterialMaps exact(const GroundTruthMaps& t, const ImageF& input) {
  MaterialMaps m;
  m.kd = m.kd_refined = t.kd;
  m.ks = t.ks;
  m.alpha = t.alpha;
  m.rgb = m.rgb_refined = input;
  m.segment = t.segment;
  m.covered = ImageF(kWidth, kHeight, 1, 1.0f);
  return m;
}

TEST(MaterialEvaluation, ExactEstimatesScorePerfectly) {
  const GroundTruthMaps t = truth();
  const ImageF input(kWidth, kHeight, 3, 0.25f);
  MaterialEvaluation evaluation(10);
  evaluation.add_frame(0, exact(t, input), t, input);
  const auto table = evaluation.table();
  ASSERT_EQ(table.size(), 2u);
  for (const auto& [object, scores] : table)
    for (Quantity q : kQuantities) {
      EXPECT_EQ(scores.at(q).l1, 0.0) << quantity_name(q);
      EXPECT_EQ(scores.at(q).rmse, 0.0);
      EXPECT_DOUBLE_EQ(scores.at(q).psnr, 100.0) << "capped";
      EXPECT_NEAR(scores.at(q).ssim, 1.0, 1e-9);
      EXPECT_DOUBLE_EQ(scores.at(q).psnr_frame, 100.0);
      EXPECT_NEAR(scores.at(q).ssim_frame, 1.0, 1e-9);
      EXPECT_NEAR(scores.at(q).ssim_object, 1.0, 1e-9);
    }
}

TEST(MaterialEvaluation, ConstantErrorGivesKnownL1RmsePsnr) {
  const GroundTruthMaps t = truth();
  const ImageF input(kWidth, kHeight, 3, 0.25f);
  MaterialMaps estimate = exact(t, input);
  for (float& v : estimate.kd.values()) v += 0.1f;
  MaterialEvaluation evaluation(10);
  evaluation.add_frame(0, estimate, t, input);
  evaluation.add_frame(1, estimate, t, input);
  const Scores kd = evaluation.average().at(Quantity::kd);
  EXPECT_NEAR(kd.l1, 0.1, 1e-6);
  EXPECT_NEAR(kd.rmse, 0.1, 1e-6);
  EXPECT_NEAR(kd.psnr, 20.0, 1e-4);
  // Over the whole frame the error covers one half of it: MSE / 2, so 10 log10(2) dB more.
  EXPECT_NEAR(kd.psnr_frame, 20.0 + 10 * std::log10(2.0), 1e-4);
  EXPECT_GT(kd.ssim_frame, kd.ssim);
  EXPECT_LT(kd.ssim_frame, 1.0);
  EXPECT_EQ(evaluation.average().at(Quantity::ks).l1, 0.0);
  // Figure 4's series: per object, per frame, estimate and truth of the red channel.
  ASSERT_EQ(evaluation.series().at(1).size(), 2u);
  EXPECT_NEAR(evaluation.series().at(1)[1].kd, 0.5, 1e-6);
  EXPECT_NEAR(evaluation.series().at(1)[1].true_kd, 0.4, 1e-6);
}

TEST(MaterialEvaluation, WholeFrameSsimEqualsSsimOfTheMaskedFrames) {
  // A 12 x 10 object inside the frame with a textured error, so that the shortcut (SSIM over the
  // object's box grown by twice the window radius) must match the SSIM of the full masked frames.
  GroundTruthMaps t = truth();
  for (int y = 0; y < kHeight; ++y)
    for (int x = 0; x < kWidth; ++x)
      t.segment.at(x, y, 0) = x >= 14 && x < 26 && y >= 10 && y < 20 ? 1 : 0;
  const ImageF input(kWidth, kHeight, 3, 0.25f);
  MaterialMaps estimate = exact(t, input);
  for (int y = 0; y < kHeight; ++y)
    for (int x = 0; x < kWidth; ++x) estimate.alpha.at(x, y, 0) += 0.05f * ((x * 7 + y * 3) % 5);
  MaterialEvaluation evaluation(10);
  evaluation.add_frame(0, estimate, t, input);
  ImageF truth_masked(kWidth, kHeight, 1), estimate_masked(kWidth, kHeight, 1);
  for (int y = 0; y < kHeight; ++y)
    for (int x = 0; x < kWidth; ++x)
      if (t.segment.at(x, y, 0) == 1) {
        truth_masked.at(x, y, 0) = t.alpha.at(x, y, 0);
        estimate_masked.at(x, y, 0) = estimate.alpha.at(x, y, 0);
      }
  EXPECT_NEAR(evaluation.average().at(Quantity::alpha).ssim_frame,
              denoise::ssim(truth_masked, estimate_masked), 1e-9);
  // The object-alone SSIM is the same frames' SSIM averaged over the object's pixels.
  ImageF object(kWidth, kHeight, 1);
  for (int y = 0; y < kHeight; ++y)
    for (int x = 0; x < kWidth; ++x) object.at(x, y, 0) = t.segment.at(x, y, 0) == 1;
  EXPECT_NEAR(evaluation.average().at(Quantity::alpha).ssim_object,
              denoise::ssim(truth_masked, estimate_masked, &object), 1e-9);
}

TEST(MaterialEvaluation, ObjectSsimIgnoresWhatLiesAroundTheObject) {
  // The frame split along its diagonal, so that object 1's box holds part of object 2. Object
  // 1's estimate is exact, object 2's is off: object 1's crop SSIM sees object 2 in the windows
  // across their border, its object-alone SSIM does not.
  GroundTruthMaps t = truth();
  for (int y = 0; y < kHeight; ++y)
    for (int x = 0; x < kWidth; ++x) t.segment.at(x, y, 0) = x * kHeight < y * kWidth ? 1 : 2;
  const ImageF input(kWidth, kHeight, 3, 0.25f);
  MaterialMaps estimate = exact(t, input);
  for (int y = 0; y < kHeight; ++y)
    for (int x = 0; x < kWidth; ++x)
      if (t.segment.at(x, y, 0) == 2) estimate.ks.at(x, y, 0) = 0.6f;
  MaterialEvaluation evaluation(10);
  evaluation.add_frame(0, estimate, t, input);
  const Scores ks = evaluation.table().at(1).at(Quantity::ks);
  EXPECT_EQ(ks.l1, 0.0);
  EXPECT_LT(ks.ssim, 0.99);
  EXPECT_NEAR(ks.ssim_object, 1.0, 1e-9);
}

TEST(MaterialEvaluation, UncoveredAndTinyObjectsAreNotScored) {
  const GroundTruthMaps t = truth();
  const ImageF input(kWidth, kHeight, 3, 0.25f);
  MaterialMaps estimate = exact(t, input);
  // Object 2 is covered on 5 pixels only.
  for (int y = 0; y < kHeight; ++y)
    for (int x = kWidth / 2; x < kWidth; ++x) estimate.covered.at(x, y, 0) = y == 0 && x < 25;
  MaterialEvaluation evaluation(10);
  evaluation.add_frame(0, estimate, t, input);
  EXPECT_EQ(evaluation.table().size(), 1u);
  EXPECT_EQ(evaluation.table().count(1), 1u);
}

}  // namespace
}  // namespace glint::reflectance
