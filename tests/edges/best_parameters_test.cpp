// core/best_parameters.h with libtorch tensors (tested here: the edges tests link libtorch, the
// core tests do not).
#include "core/best_parameters.h"

#include <gtest/gtest.h>
#include <torch/torch.h>

namespace glint {
namespace {

TEST(BestParameters, KeepsTheLowestLossesParametersAndWritesThemBack) {
  torch::nn::Linear layer(3, 2);
  BestParameters<torch::Tensor> best;
  EXPECT_EQ(best.step(), -1);
  EXPECT_FALSE(best.restore(layer->parameters())) << "nothing kept yet";

  const auto set_all = [&](float value) {
    torch::NoGradGuard no_grad;
    for (torch::Tensor& p : layer->parameters()) p.fill_(value);
  };
  set_all(1.0f);
  EXPECT_TRUE(best.offer(layer->parameters(), 0.5, 10));
  set_all(2.0f);
  EXPECT_FALSE(best.offer(layer->parameters(), 0.7, 20)) << "a higher loss";
  EXPECT_FALSE(best.offer(layer->parameters(), 0.5, 30)) << "an equal loss";
  set_all(3.0f);  // the module trains on
  EXPECT_EQ(best.step(), 10);
  EXPECT_EQ(best.loss(), 0.5);

  ASSERT_TRUE(best.restore(layer->parameters()));
  for (const torch::Tensor& p : layer->parameters()) {
    EXPECT_TRUE(torch::all(p == 1.0f).item<bool>());
    EXPECT_TRUE(p.requires_grad()) << "still a trainable parameter";
  }
  // The copy kept is the module's values at the offer, not a view of its storage.
  set_all(4.0f);
  ASSERT_TRUE(best.restore(layer->parameters()));
  EXPECT_TRUE(torch::all(layer->weight == 1.0f).item<bool>());
}

}  // namespace
}  // namespace glint
