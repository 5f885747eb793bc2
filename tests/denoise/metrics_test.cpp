#include "denoise/metrics.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "denoise/corruption.h"
#include "image_test_support.h"

namespace glint::denoise {
namespace {

using test::error_of;
using ::testing::HasSubstr;

constexpr double kC1 = 0.0001, kC2 = 0.0009;  // (0.01 L)², (0.03 L)², L = 1

ImageF one_channel(std::vector<float> values) {
  ImageF image(static_cast<int>(values.size()), 1, 1);
  image.values() = std::move(values);
  return image;
}

TEST(Psnr, MatchesHandComputedValues) {
  const ImageF reference = test::constant(8, 6, 3, 0.5f);
  EXPECT_NEAR(psnr(reference, test::constant(8, 6, 3, 0.6f)), 20.0, 1e-5);  // MSE 0.01
  EXPECT_NEAR(psnr(one_channel({0.f, 0.f}), one_channel({0.1f, 0.3f})),     // MSE 0.05
              10 * std::log10(20.0), 1e-5);
  EXPECT_EQ(psnr(reference, reference), INFINITY);
}

TEST(Psnr, MaskedCountsOnlyTheMaskedPixels) {
  const ImageF reference = test::constant(10, 10, 2, 0.2f);
  ImageF candidate = test::constant(10, 10, 2, 0.5f);  // off by 0.3 ...
  const ImageF mask = test::box_mask(10, 10, 0, 0, 4, 10);
  for (int c = 0; c < 2; ++c) {
    for (int y = 0; y < 10; ++y) {
      for (int x = 0; x < 4; ++x) candidate.at(x, y, c) = 0.3f;  // ... except off by 0.1 here
    }
  }
  EXPECT_NEAR(psnr(reference, candidate, &mask), 20.0, 1e-5);
  EXPECT_NEAR(psnr(reference, candidate), -10 * std::log10(0.4 * 0.01 + 0.6 * 0.09), 1e-5);
}

TEST(Psnr, MismatchesAndEmptyMasksAreErrors) {
  const ImageF reference = test::constant(8, 8, 3, 0.5f);
  EXPECT_EQ(error_of([&] { psnr(reference, test::constant(8, 7, 3, 0.5f)); }).file(), "test image");
  EXPECT_THAT(error_of([&] { psnr(reference, test::constant(8, 8, 1, 0.5f)); }).reason(),
              HasSubstr("8x8x1"));
  const ImageF small_mask = test::constant(4, 4, 1, 1.f);
  EXPECT_EQ(error_of([&] { psnr(reference, reference, &small_mask); }).file(), "mask");
  const ImageF empty_mask = test::constant(8, 8, 1, 0.5f);  // nothing > 0.5
  EXPECT_THAT(error_of([&] { ssim(reference, reference, &empty_mask); }).reason(),
              HasSubstr("selects no pixel"));
  EXPECT_THAT(error_of([] { psnr(ImageF(), ImageF()); }).reason(), HasSubstr("no pixels"));
  ImageF broken = reference;
  broken.at(2, 3, 1) = NAN;
  EXPECT_EQ(error_of([&] { ssim(reference, broken); }).file(), "test image");
}

TEST(Ssim, IdenticalImagesScoreOne) {
  const ImageF image = test::random_image(30, 20, 3, 1);
  EXPECT_NEAR(ssim(image, image), 1.0, 1e-12);
}

TEST(Ssim, ConstantImagesReduceToTheLuminanceTerm) {
  auto expected = [](double a, double b) { return (2 * a * b + kC1) / (a * a + b * b + kC1); };
  EXPECT_NEAR(ssim(test::constant(16, 16, 1, 0.3f), test::constant(16, 16, 1, 0.6f)),
              expected(0.3f, 0.6f), 1e-9);
  ImageF a(16, 16, 2), b(16, 16, 2);
  std::fill_n(a.plane(0), 256, 0.2f), std::fill_n(b.plane(0), 256, 0.9f);
  std::fill_n(a.plane(1), 256, 0.5f), std::fill_n(b.plane(1), 256, 0.4f);
  EXPECT_NEAR(ssim(a, b), (expected(0.2f, 0.9f) + expected(0.5f, 0.4f)) / 2, 1e-9);
}

// Wang et al.'s SSIM written out: Gaussian weights over the window cut to the image, the map
// averaged over the masked pixels (all without a mask) per channel, then over the channels.
double ssim_by_definition(const ImageF& x, const ImageF& y, const ImageF* mask = nullptr) {
  double total = 0;
  for (int c = 0; c < x.channels(); ++c) {
    double sum = 0, count = 0;
    for (int py = 0; py < x.height(); ++py) {
      for (int px = 0; px < x.width(); ++px) {
        if (mask != nullptr && mask->at(px, py, 0) <= 0.5f) continue;
        double w_sum = 0, mx = 0, my = 0, xx = 0, yy = 0, xy = 0;
        for (int qy = std::max(0, py - 5); qy <= std::min(x.height() - 1, py + 5); ++qy) {
          for (int qx = std::max(0, px - 5); qx <= std::min(x.width() - 1, px + 5); ++qx) {
            const double d2 = (qx - px) * (qx - px) + (qy - py) * (qy - py);
            const double w = std::exp(-d2 / (2 * 1.5 * 1.5));
            const double a = x.at(qx, qy, c), b = y.at(qx, qy, c);
            w_sum += w, mx += w * a, my += w * b, xx += w * a * a, yy += w * b * b, xy += w * a * b;
          }
        }
        mx /= w_sum, my /= w_sum, xx /= w_sum, yy /= w_sum, xy /= w_sum;
        const double vx = xx - mx * mx, vy = yy - my * my, cxy = xy - mx * my;
        sum +=
            (2 * mx * my + kC1) * (2 * cxy + kC2) / ((mx * mx + my * my + kC1) * (vx + vy + kC2));
        ++count;
      }
    }
    total += sum / count;
  }
  return total / x.channels();
}

TEST(Ssim, AgreesWithTheDefinitionOnANoisyPair) {
  const ImageF clean = test::random_image(23, 17, 1, 4, 0.2f, 0.8f);
  const ImageF noisy = add_noise_in_mask(clean, test::constant(23, 17, 1, 1.f), 0.1, 5);
  const double value = ssim(clean, noisy);
  EXPECT_NEAR(value, ssim_by_definition(clean, noisy), 1e-9);
  EXPECT_GT(value, 0.3);
  EXPECT_LT(value, 0.95);
  const ImageF noisier = add_noise_in_mask(clean, test::constant(23, 17, 1, 1.f), 0.3, 5);
  EXPECT_LT(ssim(clean, noisier), value);
}

// Odd sizes, two channels and a ragged mask that reaches the corners: every window cut at
// one border, at two, or not at all.
TEST(Ssim, AgreesWithTheDefinitionWithAMaskAndSeveralChannels) {
  const ImageF clean = test::random_image(23, 17, 2, 7, 0.1f, 0.9f);
  const ImageF noisy = add_noise_in_mask(clean, test::constant(23, 17, 1, 1.f), 0.15, 8);
  ImageF mask = test::random_image(23, 17, 1, 9);  // about half the pixels > 0.5
  mask.at(0, 0, 0) = mask.at(22, 16, 0) = 1.f;
  EXPECT_NEAR(ssim(clean, noisy, &mask), ssim_by_definition(clean, noisy, &mask), 1e-12);
  EXPECT_NEAR(ssim(clean, noisy), ssim_by_definition(clean, noisy), 1e-12);
}

TEST(Ssim, MaskedAveragesOnlyTheMaskedPixels) {
  const ImageF reference = test::random_image(40, 20, 3, 6);
  ImageF inverted_right = reference;
  for (int c = 0; c < 3; ++c) {
    for (int y = 0; y < 20; ++y) {
      for (int x = 20; x < 40; ++x) inverted_right.at(x, y, c) = 1 - reference.at(x, y, c);
    }
  }
  const ImageF far_left = test::box_mask(40, 20, 0, 0, 10, 20);  // windows never reach x >= 20
  EXPECT_NEAR(ssim(reference, inverted_right, &far_left), 1.0, 1e-12);
  EXPECT_LT(ssim(reference, inverted_right), 0.7);
}

TEST(RocAuc, PerfectInvertedTiedAndHandComputedScores) {
  const ImageF truth = test::box_mask(12, 8, 3, 2, 9, 6);
  ImageF inverted = truth;
  for (float& v : inverted.values()) v = 1 - v;
  EXPECT_EQ(roc_auc(truth, truth), 1.0);
  EXPECT_EQ(roc_auc(inverted, truth), 0.0);
  EXPECT_EQ(roc_auc(test::constant(12, 8, 1, 0.3f), truth), 0.5);
  // positives 0.35, 0.8 against negatives 0.1, 0.4: 3 of 4 pairs ordered.
  EXPECT_EQ(roc_auc(one_channel({0.1f, 0.4f, 0.35f, 0.8f}), one_channel({0, 0, 1, 1})), 0.75);
  // positives 0.5, 0.9 against negatives 0.5, 0.2: one tie counts half.
  EXPECT_EQ(roc_auc(one_channel({0.5f, 0.5f, 0.2f, 0.9f}), one_channel({1, 0, 0, 1})), 0.875);
}

TEST(RocAuc, RandomScoresGiveAboutAHalf) {
  const ImageF truth = test::box_mask(100, 100, 0, 0, 30, 100);
  EXPECT_NEAR(roc_auc(test::random_image(100, 100, 1, 9), truth), 0.5, 0.03);
}

TEST(RocAuc, DegenerateTruthAndMismatchesAreErrors) {
  const ImageF score = test::random_image(6, 6, 1, 2);
  EXPECT_THAT(error_of([&] { roc_auc(score, test::constant(6, 6, 1, 0.f)); }).reason(),
              HasSubstr("no positive"));
  EXPECT_THAT(error_of([&] { roc_auc(score, test::constant(6, 6, 1, 1.f)); }).reason(),
              HasSubstr("no negative"));
  EXPECT_EQ(error_of([&] { roc_auc(score, test::constant(6, 5, 1, 1.f)); }).file(), "truth mask");
  EXPECT_EQ(error_of([&] { roc_auc(test::constant(6, 6, 3, 1.f), score); }).file(), "score map");
  ImageF broken = score;
  broken.values()[4] = NAN;
  EXPECT_THAT(error_of([&] { roc_auc(broken, test::box_mask(6, 6, 0, 0, 3, 6)); }).reason(),
              HasSubstr("non-finite"));
}

}  // namespace
}  // namespace glint::denoise
