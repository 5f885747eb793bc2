#pragma once
// A network's parameters at its lowest validation loss so far, put back once training ends
// (early stopping that keeps the best weights): the trainers of BoundED's MLP and of the
// HemiCNN. Templated on the tensor type, so that core itself does not depend on libtorch.
#include <cstddef>
#include <limits>
#include <vector>

namespace glint {

template <class Tensor>
class BestParameters {
 public:
  // Copies `parameters` (a module's, e.g. net->parameters()) when `loss` is below every loss
  // offered before, with the training step it was reached at; true then.
  bool offer(const std::vector<Tensor>& parameters, double loss, int step) {
    if (!(loss < loss_)) return false;
    loss_ = loss;
    step_ = step;
    kept_.clear();
    for (const Tensor& p : parameters) kept_.push_back(p.detach().clone());
    return true;
  }

  // Writes the kept values into `parameters` (which share their storage with the module's);
  // false when none were kept. Through .data(), which autograd does not track.
  bool restore(const std::vector<Tensor>& parameters) const {
    if (kept_.empty()) return false;
    for (std::size_t i = 0; i < parameters.size(); ++i) parameters[i].data().copy_(kept_[i]);
    return true;
  }

  double loss() const { return loss_; }
  int step() const { return step_; }  // -1 before the first offer

 private:
  double loss_ = std::numeric_limits<double>::infinity();
  int step_ = -1;
  std::vector<Tensor> kept_;
};

}  // namespace glint
