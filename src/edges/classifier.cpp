#include "edges/classifier.h"

#include <tbb/enumerable_thread_specific.h>

#include <algorithm>
#include <string>

#include "core/error.h"
#include "core/timer.h"

namespace glint::edges {
namespace {

// A result for n points: labels, and probability columns with boundary 0 until set.
Classification sized_result(std::size_t n) {
  Classification result;
  result.labels.resize(n);
  result.p_sharp.resize(n);
  result.p_boundary.assign(n, 0.f);
  return result;
}

// One point's softmax probabilities (class order) into the result's columns.
void keep_probabilities(Classification& result, std::size_t point, const float* p,
                        std::size_t classes) {
  result.p_sharp[point] = p[1];
  if (classes > 2) result.p_boundary[point] = p[2];
}

}  // namespace

Classification classify(const PointCloud& cloud, const Model& model,
                        const std::vector<int>& scales) {
  FeatureParams params;
  params.scales = scales.empty() ? model.config.scales : scales;
  if (params.scales.size() != model.config.scales.size()) {
    throw Error("", "--scales",
                "the model was trained on " + std::to_string(model.config.scales.size()) +
                    " scales; got " + std::to_string(params.scales.size()));
  }
  model.check();
  const std::size_t classes = static_cast<std::size_t>(model.config.classes);
  Classification result = sized_result(cloud.size());

  // The network runs on each block of features as it is computed, so the rows are never all
  // stored; each thread's time is split between the two stages to report them apart.
  struct Worker {
    Model::PredictScratch scratch;
    std::vector<float> probabilities;
    std::vector<std::uint8_t> labels;
    double network_s = 0;
  };
  tbb::enumerable_thread_specific<Worker> workers([classes] {
    Worker worker;
    worker.probabilities.resize(Model::kBatch * classes);
    worker.labels.resize(Model::kBatch);
    return worker;
  });
  const Stopwatch watch;
  compute_features_in_blocks(
      cloud, params, Model::kBatch,
      [&](const std::uint32_t* points, const float* rows, std::size_t count) {
        Worker& worker = workers.local();
        const Stopwatch network_watch;
        model.predict_rows(rows, count, worker.probabilities.data(), worker.labels.data(),
                           worker.scratch);
        for (std::size_t b = 0; b < count; ++b) {
          result.labels[points[b]] = worker.labels[b];
          keep_probabilities(result, points[b], worker.probabilities.data() + b * classes, classes);
        }
        worker.network_s += network_watch.elapsed_s();
      });
  const double total_s = watch.elapsed_s();
  double network_s = 0;
  for (const Worker& worker : workers) network_s += worker.network_s;
  const double thread_s = total_s * double(std::max<std::size_t>(1, workers.size()));
  result.inference_s = total_s * std::min(1.0, network_s / thread_s);
  result.features_s = total_s - result.inference_s;
  return result;
}

Classification classify_features(const FeatureMatrix& features, const Model& model) {
  Classification result = sized_result(features.points);
  const Stopwatch watch;
  std::vector<float> probabilities;
  model.predict(features, probabilities, result.labels);
  result.inference_s = watch.elapsed_s();

  const std::size_t classes = static_cast<std::size_t>(model.config.classes);
  for (std::size_t i = 0; i < features.points; ++i)
    keep_probabilities(result, i, probabilities.data() + i * classes, classes);
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
