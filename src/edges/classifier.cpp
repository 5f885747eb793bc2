#include "edges/classifier.h"

#include <string>

#include "core/error.h"
#include "core/timer.h"

namespace glint::edges {

Classification classify(const PointCloud& cloud, const Model& model,
                        const std::vector<int>& scales) {
  FeatureParams params;
  params.scales = scales.empty() ? model.config.scales : scales;
  if (params.scales.size() != model.config.scales.size()) {
    throw Error("", "--scales",
                "the model was trained on " + std::to_string(model.config.scales.size()) +
                    " scales; got " + std::to_string(params.scales.size()));
  }
  const Stopwatch watch;
  const FeatureMatrix features = compute_features(cloud, params);
  const double features_s = watch.elapsed_s();
  Classification result = classify_features(features, model);
  result.features_s = features_s;
  return result;
}

Classification classify_features(const FeatureMatrix& features, const Model& model) {
  Classification result;
  const Stopwatch watch;
  std::vector<float> probabilities;
  model.predict(features, probabilities, result.labels);
  result.inference_s = watch.elapsed_s();

  const std::size_t classes = static_cast<std::size_t>(model.config.classes);
  result.p_sharp.resize(features.points);
  result.p_boundary.assign(features.points, 0.f);
  for (std::size_t i = 0; i < features.points; ++i) {
    result.p_sharp[i] = probabilities[i * classes + 1];
    if (classes > 2) result.p_boundary[i] = probabilities[i * classes + 2];
  }
  return result;
}

void attach_classification(PointCloud& cloud, const Classification& result) {
  const std::size_t n = cloud.size();
  std::vector<std::uint8_t> red(n, 200), green(n, 200), blue(n, 200);
  for (std::size_t i = 0; i < n; ++i) {
    if (result.labels[i] == 1) {
      red[i] = 230, green[i] = 30, blue[i] = 30;
    } else if (result.labels[i] == 2) {
      red[i] = 30, green[i] = 200, blue[i] = 60;
    }
  }
  cloud.set("scalar_label", result.labels);
  cloud.set("scalar_p_sharp", result.p_sharp);
  cloud.set("scalar_p_boundary", result.p_boundary);
  cloud.set("red", std::move(red));
  cloud.set("green", std::move(green));
  cloud.set("blue", std::move(blue));
}

}  // namespace glint::edges
