// The neural denoisers: eq. (16)'s loss-weight schedule, eqs (17)-(24)'s mask and dropout
// probabilities (analytic and sampled), the U-Net's shapes, and few-iteration runs of each
// method on a 32×32 image.
#include "denoise/neural.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>

#include "core/error.h"
#include "denoise/neural_impl.h"
#include "denoise/torch_support.h"
#include "denoise/unet.h"

namespace glint::denoise {
namespace {

TEST(DecayWeight, FollowsEquation16) {
  const DecayParams p;  // κw 225, κr 0.15, κc 0.02
  EXPECT_DOUBLE_EQ(decay_weight(0, 0.0, p), 1.0);
  EXPECT_DOUBLE_EQ(decay_weight(224, 0.0, p), 1.0);
  EXPECT_DOUBLE_EQ(decay_weight(225, 0.0, p), 1.0);  // base^0
  EXPECT_NEAR(decay_weight(235, 0.0, p), std::pow(0.9, 1.5) * 0.98 + 0.02, 1e-12);
  EXPECT_NEAR(decay_weight(235, 0.5, p), std::pow(0.95, 1.5) * 0.98 + 0.02, 1e-12);
  // Important pixels keep full weight; noisy ones converge to κc, never below.
  EXPECT_DOUBLE_EQ(decay_weight(100000, 1.0, p), 1.0);
  EXPECT_NEAR(decay_weight(100000, 0.0, p), 0.02, 1e-12);
  for (int i = 225; i < 2000; i += 50)
    EXPECT_GE(decay_weight(i, 0.3, p), decay_weight(i + 50, 0.3, p));
}

TEST(MaskProbabilities, PlainSelf2SelfIsTheSpecialCase) {
  MaskParams plain;
  plain.discard = 1.0;
  const MaskProbabilities q = mask_probabilities(0.0, plain);
  EXPECT_DOUBLE_EQ(q.both, 0.0);
  EXPECT_DOUBLE_EQ(q.input_only, 0.7);
  EXPECT_NEAR(q.target_only, 0.3, 1e-15);
  EXPECT_NEAR(q.neither, 0.0, 1e-15);
}

TEST(MaskProbabilities, SumToOneAndInterpolate) {
  const MaskParams p;  // p_m 0.7, p_d 0.01, κm 2
  for (double m : {0.0, 0.3, 0.5, 0.9, 1.0}) {
    const double p_imp = importance_probability(m, p.exponent);
    EXPECT_DOUBLE_EQ(p_imp, m * m);
    const MaskProbabilities q = mask_probabilities(p_imp, p);
    EXPECT_NEAR(q.both + q.input_only + q.target_only + q.neither, 1.0, 1e-12);
    EXPECT_DOUBLE_EQ(q.both, p_imp);                              // eq. (20)
    EXPECT_NEAR(q.input_only, 0.7 * 0.01 * (1 - p_imp), 1e-15);   // eq. (21)
    EXPECT_NEAR(q.target_only, 0.3 * 0.01 * (1 - p_imp), 1e-15);  // eq. (22)
    // eqs (17)-(18): marginals.
    EXPECT_NEAR(q.both + q.input_only, p_imp + (1 - p_imp) * 0.7 * 0.01, 1e-15);
    EXPECT_NEAR(q.both + q.target_only, p_imp + (1 - p_imp) * 0.3 * 0.01, 1e-15);
  }
  EXPECT_DOUBLE_EQ(modulated_dropout(1.0, 0.3), 0.0);  // eq. (24)
  EXPECT_DOUBLE_EQ(modulated_dropout(0.0, 0.3), 0.3);
  EXPECT_DOUBLE_EQ(modulated_dropout(0.25, 0.4), 0.3);
}

TEST(SampleMasks, EmpiricalFrequenciesMatchEquations20To23) {
  torch::manual_seed(7);
  MaskParams p;
  p.discard = 0.5;  // large enough that every case is frequent
  const int n = 400000;
  for (double p_imp : {0.0, 0.25, 0.8}) {
    const MaskProbabilities q = mask_probabilities(p_imp, p);
    const auto full = [n](double v) { return torch::full({1, 1, 1, n}, v); };
    const SampledMasks masks = sample_masks(full(q.both), full(q.both + q.input_only),
                                            full(q.both + q.input_only + q.target_only));
    const auto freq = [n](const torch::Tensor& t) { return t.sum().item<double>() / n; };
    const torch::Tensor in = masks.input, tg = masks.target;
    const double tolerance = 4.0 * std::sqrt(0.25 / n);  // 4 standard deviations
    EXPECT_NEAR(freq(in * tg), q.both, tolerance) << p_imp;
    EXPECT_NEAR(freq(in * (1 - tg)), q.input_only, tolerance) << p_imp;
    EXPECT_NEAR(freq((1 - in) * tg), q.target_only, tolerance) << p_imp;
    EXPECT_NEAR(freq((1 - in) * (1 - tg)), q.neither, tolerance) << p_imp;
  }
}

TEST(PixelDropout, ZeroRateIsIdentityAndRatesAreKeptInExpectation) {
  torch::manual_seed(3);
  const torch::Tensor x = torch::ones({1, 8, 64, 64});
  EXPECT_TRUE(torch::equal(pixel_dropout(x, torch::zeros({1, 1, 64, 64})), x));
  const torch::Tensor rate = torch::full({1, 1, 64, 64}, 0.3);
  const torch::Tensor y = pixel_dropout(x, rate);
  EXPECT_NEAR((y == 0).to(torch::kFloat32).mean().item<double>(), 0.3, 0.02);
  EXPECT_NEAR(y.mean().item<double>(), 1.0, 0.05);  // inverted dropout keeps the mean
}

TEST(UNet, ShapesAndRange) {
  torch::manual_seed(1);
  UNet net(5, 3, UNetConfig{3, 8, 4});
  const torch::Tensor y = net->forward(torch::rand({1, 5, 24, 40}), {});
  EXPECT_EQ(y.sizes(), (std::vector<int64_t>{1, 3, 24, 40}));
  EXPECT_GE(y.min().item<float>(), 0.f);
  EXPECT_LE(y.max().item<float>(), 1.f);
  EXPECT_GT(parameter_count(*net), 1000);
  // Odd sizes are padded to the multiple and cropped back.
  const torch::Tensor odd = torch::rand({1, 1, 13, 21});
  const torch::Tensor padded = pad_to_multiple(odd, 8);
  EXPECT_EQ(padded.sizes(), (std::vector<int64_t>{1, 1, 16, 24}));
  EXPECT_TRUE(torch::equal(crop_to(padded, 13, 21), odd));
}

TEST(TorchSupport, ImageRoundTripAndDevices) {
  ImageF image(5, 3, 2);
  for (std::size_t i = 0; i < image.values().size(); ++i) image.values()[i] = 0.01f * i;
  const torch::Tensor t = to_tensor(image, torch::kCPU);
  EXPECT_EQ(t.sizes(), (std::vector<int64_t>{1, 2, 3, 5}));
  EXPECT_FLOAT_EQ(t[0][1][2][4].item<float>(), image.at(4, 2, 1));
  EXPECT_EQ(to_image(t).values(), image.values());
  EXPECT_EQ(resolve_device("cpu"), torch::Device(torch::kCPU));
  EXPECT_THROW(resolve_device("tpu"), Error);
  if (!torch::cuda::is_available()) {
    EXPECT_THROW(resolve_device("cuda"), Error);
  }
}

// A 32×32 colour test image: smooth ramps, noisy on the left half.
struct SmokeImages {
  ImageF noisy{32, 32, 3};
  ImageF guidance{32, 32, 1, 1.f};
};

SmokeImages smoke_images() {
  SmokeImages s;
  std::mt19937 random(5);
  std::normal_distribution<float> noise(0.f, 0.15f);
  for (int c = 0; c < 3; ++c)
    for (int y = 0; y < 32; ++y)
      for (int x = 0; x < 32; ++x) {
        const bool noisy = x < 16;
        s.noisy.at(x, y, c) =
            std::clamp(0.2f + 0.02f * x + 0.1f * c + (noisy ? noise(random) : 0.f), 0.f, 1.f);
        if (c == 0) s.guidance.at(x, y, 0) = noisy ? 0.f : 1.f;
      }
  return s;
}

class NeuralSmoke : public ::testing::TestWithParam<NeuralMethod> {};

TEST_P(NeuralSmoke, FewIterationsGiveAFiniteImageOfTheInputsSize) {
  const SmokeImages s = smoke_images();
  NeuralParams params = neural_preset(GetParam(), "fast");
  params.net = UNetConfig{2, 8, 2};
  params.iterations = 6;
  params.predictions = 3;
  params.decay.warmup = 2;  // exercise the decay branch
  params.device = "cpu";
  int snapshots = 0;
  params.snapshot_every = 3;
  params.snapshot = [&](int, const ImageF& estimate) {
    EXPECT_TRUE(estimate.same_size(s.noisy));
    ++snapshots;
  };
  NeuralStats stats;
  const ImageF out = denoise_neural(s.noisy, &s.guidance, params, &stats);
  ASSERT_TRUE(out.same_size(s.noisy));
  ASSERT_EQ(out.channels(), 3);
  for (float v : out.values()) {
    ASSERT_TRUE(std::isfinite(v));
    ASSERT_GE(v, 0.f);
    ASSERT_LE(v, 1.f);
  }
  EXPECT_EQ(snapshots, 2);
  EXPECT_EQ(stats.iterations, 6);
  EXPECT_EQ(stats.device, "cpu");
  EXPECT_GT(stats.parameters, 0);
}

INSTANTIATE_TEST_SUITE_P(AllMethods, NeuralSmoke,
                         ::testing::Values(NeuralMethod::dip, NeuralMethod::guided_dip,
                                           NeuralMethod::s2s, NeuralMethod::guided_s2s),
                         [](const auto& info) {
                           std::string name = method_name(info.param);
                           std::replace(name.begin(), name.end(), '-', '_');
                           return name;
                         });

TEST(Neural, SameSeedSameResult) {
  const SmokeImages s = smoke_images();
  NeuralParams params = neural_preset(NeuralMethod::guided_s2s, "fast");
  params.net = UNetConfig{2, 8, 2};
  params.iterations = 3;
  params.predictions = 2;
  params.device = "cpu";
  const ImageF a = denoise_neural(s.noisy, &s.guidance, params);
  const ImageF b = denoise_neural(s.noisy, &s.guidance, params);
  EXPECT_EQ(a.values(), b.values());
}

// Weighted averaging (eq. (14) with the rate scaled by w_dec): once a pixel's weight is 0 its
// estimate stays what it was, while pixels of weight 1 keep following the output.
TEST(Neural, WeightedAveragingKeepsTheEstimateOfLetGoPixels) {
  const SmokeImages s = smoke_images();
  NeuralParams params = neural_preset(NeuralMethod::guided_dip, "fast");
  params.net = UNetConfig{2, 8, 2};
  params.device = "cpu";
  params.weighted_averaging = true;
  params.decay = DecayParams{0, 1000.0, 0.0};  // m = 0: w = 0.9^(1000 i) = 0 from step 1 on
  params.iterations = 1;
  const ImageF first = denoise_neural(s.noisy, &s.guidance, params);
  params.iterations = 6;
  const ImageF later = denoise_neural(s.noisy, &s.guidance, params);
  double moved_clean = 0;
  for (int c = 0; c < 3; ++c)
    for (int y = 0; y < 32; ++y)
      for (int x = 0; x < 32; ++x) {
        if (s.guidance.at(x, y, 0) < 0.5f)
          ASSERT_FLOAT_EQ(later.at(x, y, c), first.at(x, y, c)) << x << "," << y;
        else
          moved_clean += std::abs(later.at(x, y, c) - first.at(x, y, c));
      }
  EXPECT_GT(moved_clean, 0.0);
}

TEST(Neural, BadInputsAreErrors) {
  const SmokeImages s = smoke_images();
  NeuralParams params = neural_preset(NeuralMethod::guided_dip, "fast");
  params.iterations = 1;
  EXPECT_THROW(denoise_neural(s.noisy, nullptr, params), Error);  // guided without a map
  const ImageF wrong(16, 32, 1, 1.f);
  EXPECT_THROW(denoise_neural(s.noisy, &wrong, params), Error);
  EXPECT_THROW(denoise_neural(ImageF(), &s.guidance, params), Error);
  // The full net's 5 halvings leave a 32x32 image 1x1 at its deepest level: a clear error, not
  // libtorch's.
  NeuralParams full = neural_preset(NeuralMethod::dip, "full");
  full.iterations = 1;
  EXPECT_THROW(denoise_neural(ImageF(32, 32, 3, 0.5f), nullptr, full), Error);
  EXPECT_THROW(denoise_neural(ImageF(64, 32, 3, 0.5f), nullptr, full), Error);
  EXPECT_THROW(neural_preset(NeuralMethod::dip, "medium"), Error);
  EXPECT_THROW(parse_neural_method("bm3d"), Error);
  EXPECT_EQ(parse_neural_method("guided-s2s"), NeuralMethod::guided_s2s);
  // Plain S2S is p_d = 1 (§3.3).
  EXPECT_DOUBLE_EQ(neural_preset(NeuralMethod::s2s, "full").masks.discard, 1.0);
  EXPECT_DOUBLE_EQ(neural_preset(NeuralMethod::guided_s2s, "full").masks.discard, 0.01);
}

}  // namespace
}  // namespace glint::denoise
