#include "edges/classifier.h"

#include <tbb/enumerable_thread_specific.h>

#include <algorithm>
#include <functional>
#include <string>

#include "core/error.h"
#include "core/timer.h"
#include "geometry/neighbourhoods.h"

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

std::vector<int> scales_for(const Model& model, const std::vector<int>& scales) {
  if (!scales.empty() && scales.size() != model.config.scales.size()) {
    throw Error("", "--scales",
                "the model was trained on " + std::to_string(model.config.scales.size()) +
                    " scales; got " + std::to_string(scales.size()));
  }
  return scales.empty() ? model.config.scales : scales;
}

// The networks a pass runs, chosen once the cloud's neighbour search is built and before any
// row (a sampling gate chooses from spacings the search finds).
using NetworkChoice =
    std::function<std::vector<const Model*>(const geometry::NeighbourhoodSearch&)>;

// Computes the features once and runs every chosen network on each block of them as it is
// computed, so the rows are never all stored; one result per network. `model` gives the
// features and the classes (a gate's networks share them). With `noise_values`, also every
// point's edges::noise_statistic. Each thread's time is split between the two stages to report
// them apart.
std::vector<Classification> run_networks(const PointCloud& cloud, const Model& model,
                                         const std::vector<int>& scales,
                                         const NetworkChoice& choose,
                                         std::vector<float>* noise_values) {
  FeatureParams params = model.config.feature_params();
  params.scales = scales;
  const int scale_count = static_cast<int>(scales.size());
  const int per_scale = params.per_scale();
  const std::size_t row_size = params.row_size();
  const std::size_t classes = static_cast<std::size_t>(model.config.classes);
  std::vector<const Model*> networks;
  std::vector<Classification> results;
  if (noise_values) noise_values->resize(cloud.size());

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
        for (std::size_t n = 0; n < networks.size(); ++n) {
          networks[n]->predict_rows(rows, count, worker.probabilities.data(), worker.labels.data(),
                                    worker.scratch);
          Classification& result = results[n];
          for (std::size_t b = 0; b < count; ++b) {
            result.labels[points[b]] = worker.labels[b];
            keep_probabilities(result, points[b], worker.probabilities.data() + b * classes,
                               classes);
          }
        }
        if (noise_values)
          for (std::size_t b = 0; b < count; ++b)
            (*noise_values)[points[b]] =
                noise_statistic(rows + b * row_size, scale_count, per_scale);
        worker.network_s += network_watch.elapsed_s();
      },
      [&](const geometry::NeighbourhoodSearch& search) {
        networks = choose(search);
        for (std::size_t n = 0; n < networks.size(); ++n)
          results.push_back(sized_result(cloud.size()));
      });
  const double total_s = watch.elapsed_s();
  double network_s = 0;
  for (const Worker& worker : workers) network_s += worker.network_s;
  const double thread_s = total_s * double(std::max<std::size_t>(1, workers.size()));
  for (Classification& result : results) {
    result.inference_s = total_s * std::min(1.0, network_s / thread_s);
    result.features_s = total_s - result.inference_s;
  }
  return results;
}

// The same networks whatever the cloud.
NetworkChoice fixed(std::vector<const Model*> networks) {
  return [networks](const geometry::NeighbourhoodSearch&) { return networks; };
}

// The tally of a sampling gate over the points `reads` marks, their spacings found by `search`
// (built for the largest scale: the spacing is the one FeatureMatrix::squared_spacings holds).
GateTally spacing_tally(const Model& model, const geometry::NeighbourhoodSearch& search,
                        std::span<const std::uint8_t> reads, int largest_scale) {
  const int k = std::min(kAreaSpacingNeighbour + 1, largest_scale);
  const std::vector<float> spacings = search.kth_nearest_squared_distances(k, {}, reads);
  GateTally tally = model.new_tally();
  for (std::size_t i = 0; i < reads.size(); ++i)
    if (reads[i]) tally.add(spacings[i]);
  return tally;
}

// The gate's tally of every point's value.
GateTally tally_of(const Model& model, const std::vector<float>& gate_values) {
  GateTally tally = model.new_tally();
  for (const float value : gate_values) tally.add(value);
  return tally;
}

// Records the gate's statistic and choice in a result.
void keep_gate_choice(Classification& result, const GateTally& tally) {
  result.gate_statistic = tally.statistic();
  result.gate_network_answered = tally.gate_network_answers();
}

// The points of a whole cloud that a sampling gate reads.
std::vector<std::uint8_t> whole_cloud_reads(std::size_t points) {
  std::vector<std::uint8_t> reads(points);
  for (std::size_t i = 0; i < points; ++i) reads[i] = sampling_gate_reads(i, points) ? 1 : 0;
  return reads;
}

}  // namespace

GatedClassification classify_gated(const PointCloud& cloud, const Model& model,
                                   const std::vector<int>& scales) {
  if (!model.gated() || model.gate_kind != GateKind::noise)
    throw Error("model", "gate", "both answers are kept for a noise gate only");
  model.check();
  GatedClassification result;
  std::vector<Classification> both =
      run_networks(cloud, model, scales_for(model, scales),
                   fixed({&model, model.gate_network.get()}), &result.gate_values);
  result.model_network = std::move(both[0]);
  result.gate_network = std::move(both[1]);
  return result;
}

GateTally sampling_gate_tally(const PointCloud& cloud, const Model& model,
                              std::span<const std::uint8_t> reads, const std::vector<int>& scales) {
  if (!model.gated() || model.gate_kind != GateKind::sampling)
    throw Error("model", "gate", "the model has no sampling gate");
  const int largest_scale = scales_for(model, scales).front();
  // Cells sized as for the features: a grid sized for the small k sends the queries of sparse
  // parts to a k-d tree built for them alone.
  geometry::NeighbourhoodParams params;
  params.k = largest_scale;
  return spacing_tally(model, geometry::NeighbourhoodSearch(cloud, params), reads, largest_scale);
}

Classification classify_with_network(const PointCloud& cloud, const Model& model, bool gate_network,
                                     const std::vector<int>& scales) {
  model.check();
  if (gate_network && !model.gated()) throw Error("model", "gate", "the model has no gate");
  const Model* network = gate_network ? model.gate_network.get() : &model;
  return std::move(
      run_networks(cloud, model, scales_for(model, scales), fixed({network}), nullptr)[0]);
}

Classification classify(const PointCloud& cloud, const Model& model,
                        const std::vector<int>& scales) {
  if (!model.gated()) return classify_with_network(cloud, model, false, scales);
  if (model.gate_kind == GateKind::noise) {
    GatedClassification both = classify_gated(cloud, model, scales);
    const GateTally tally = tally_of(model, both.gate_values);
    Classification result =
        std::move(tally.gate_network_answers() ? both.gate_network : both.model_network);
    keep_gate_choice(result, tally);
    return result;
  }
  // A sampling gate chooses from the spacings before the features: one network runs.
  model.check();
  const std::vector<int> chosen_scales = scales_for(model, scales);
  const std::vector<std::uint8_t> reads = whole_cloud_reads(cloud.size());
  GateTally tally = model.new_tally();
  Classification result = std::move(run_networks(
      cloud, model, chosen_scales,
      [&](const geometry::NeighbourhoodSearch& search) {
        tally = spacing_tally(model, search, reads, chosen_scales.front());
        return std::vector<const Model*>{tally.gate_network_answers() ? model.gate_network.get()
                                                                      : &model};
      },
      nullptr)[0]);
  keep_gate_choice(result, tally);
  return result;
}

Classification classify_features(const FeatureMatrix& features, const Model& model) {
  Classification result = sized_result(features.points);
  const Model* network = &model;
  if (model.gated()) {
    model.check_features(features);
    GateTally tally = model.new_tally();
    if (model.gate_kind == GateKind::noise) {
      for (std::size_t i = 0; i < features.points; ++i)
        tally.add(noise_statistic(features.row(i), features.scales, features.per_scale));
    } else {
      if (features.squared_spacings.size() != features.points)
        throw Error("features", "squared_spacings",
                    "a sampling gate needs every point's spacing (compute_features)");
      for (std::size_t i = 0; i < features.points; ++i)
        if (sampling_gate_reads(i, features.points)) tally.add(features.squared_spacings[i]);
    }
    keep_gate_choice(result, tally);
    if (result.gate_network_answered) network = model.gate_network.get();
  }
  const Stopwatch watch;
  std::vector<float> probabilities;
  network->predict(features, probabilities, result.labels);
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
