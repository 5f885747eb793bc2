#include "edges/classifier.h"

#include <fmt/format.h>
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

// The network a pass runs, chosen once the cloud's neighbour search is built and before any
// row (a gate chooses from what the search finds, and leaves in the findings what the rows
// reuse).
using NetworkChoice =
    std::function<const Model*(const geometry::NeighbourhoodSearch&, SearchFindings&)>;

// Computes the features at the chosen network's inputs and runs it on each block of them as it
// is computed, so the rows are never all stored. `model` gives the scale count and the classes
// (a chain's networks share them). Each thread's time is split between the two stages to report
// them apart.
Classification run_network(const PointCloud& cloud, const Model& model,
                           const std::vector<int>& scales, const NetworkChoice& choose) {
  FeatureParams params = model.config.feature_params();
  params.scales = scales;
  const std::size_t classes = static_cast<std::size_t>(model.config.classes);
  const Model* network = nullptr;
  Classification result;

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
        network->predict_rows(rows, count, worker.probabilities.data(), worker.labels.data(),
                              worker.scratch);
        for (std::size_t b = 0; b < count; ++b) {
          result.labels[points[b]] = worker.labels[b];
          keep_probabilities(result, points[b], worker.probabilities.data() + b * classes, classes);
        }
        worker.network_s += network_watch.elapsed_s();
      },
      [&](const geometry::NeighbourhoodSearch& search, SearchFindings& findings) {
        network = choose(search, findings);
        result = sized_result(cloud.size());
        FeatureParams chosen = network->config.feature_params();
        chosen.scales = scales;
        return chosen;
      });
  const double total_s = watch.elapsed_s();
  double network_s = 0;
  for (const Worker& worker : workers) network_s += worker.network_s;
  const double thread_s = total_s * double(std::max<std::size_t>(1, workers.size()));
  result.inference_s = total_s * std::min(1.0, network_s / thread_s);
  result.features_s = total_s - result.inference_s;
  return result;
}

// The tally of the gate `gated` holds over the points whose mask in `reads` has its kind's bit:
// their spacing to the kAreaSpacingNeighbour-th nearest other point, found with `search` (the
// features' search), or their noise statistic at `gated`'s own inputs. With `findings`, what the
// rows can reuse is left there: the spacings, and the lists the noise statistic read.
GateTally tally_of(const PointCloud& cloud, const Model& gated,
                   const geometry::NeighbourhoodSearch& search, std::span<const std::uint8_t> reads,
                   const std::vector<int>& scales, SearchFindings* findings) {
  const std::uint8_t bit = gate_read_bit(gated.gate_kind);
  std::vector<std::uint8_t> wanted(reads.size());
  for (std::size_t i = 0; i < reads.size(); ++i) wanted[i] = (reads[i] & bit) ? 1 : 0;
  GateTally tally = gated.new_tally();
  // A tile may hold none of the points a gate reads: no pass for it.
  if (std::none_of(wanted.begin(), wanted.end(), [](std::uint8_t w) { return w != 0; }))
    return tally;
  std::vector<float> values;
  const int spacing_k = std::min(kAreaSpacingNeighbour + 1, scales.front());
  if (gated.gate_kind == GateKind::sampling) {
    values = search.kth_nearest_squared_distances(spacing_k, {}, wanted);
  } else {
    FeatureParams params = gated.config.feature_params();
    params.scales = scales;
    values = noise_statistics(cloud, params, search, wanted, findings);
  }
  for (std::size_t i = 0; i < wanted.size(); ++i)
    if (wanted[i]) tally.add(values[i]);
  // Handed over, not copied: a large cloud's spacings are megabytes of fresh pages.
  if (findings && gated.gate_kind == GateKind::sampling &&
      spacing_k == area_spacing_neighbours(cloud.size())) {
    findings->spacings = std::move(values);
    findings->spaced = std::move(wanted);
  }
  return tally;
}

// The gate-read masks of a whole cloud for the gates of the model's chain.
std::vector<std::uint8_t> whole_cloud_reads(const Model& model, std::size_t points) {
  const std::vector<const Model*> chain = model.gate_chain();
  std::vector<std::uint8_t> reads(points);
  for (std::size_t i = 0; i < points; ++i) reads[i] = gate_read_mask(chain, i, points);
  return reads;
}

}  // namespace

std::uint8_t gate_read_mask(std::span<const Model* const> chain, std::uint64_t index,
                            std::uint64_t points) {
  std::uint8_t mask = 0;
  for (const Model* gated : chain)
    if (gate_reads(gated->gate_kind, index, points)) mask |= gate_read_bit(gated->gate_kind);
  return mask;
}

std::vector<GateTally> gate_tallies(const PointCloud& cloud, const Model& model,
                                    std::span<const std::uint8_t> reads,
                                    const std::vector<int>& scales) {
  if (!model.gated()) throw Error("model", "gate", "the model has no gate");
  if (reads.size() != cloud.size())
    throw Error("", "gate", fmt::format("{} read masks for {} points", reads.size(), cloud.size()));
  const std::vector<int> chosen_scales = scales_for(model, scales);
  // Cells sized as for the features: a grid sized for the sampling gate's small k sends the
  // queries of sparse parts to a k-d tree built for them alone.
  const geometry::NeighbourhoodSearch search(cloud, feature_search_params(chosen_scales));
  std::vector<GateTally> tallies;
  for (const Model* gated : model.gate_chain())
    tallies.push_back(tally_of(cloud, *gated, search, reads, chosen_scales, nullptr));
  return tallies;
}

Classification classify_ungated(const PointCloud& cloud, const Model& network,
                                const std::vector<int>& scales) {
  network.check();
  return run_network(
      cloud, network, scales_for(network, scales),
      [&](const geometry::NeighbourhoodSearch&, SearchFindings&) { return &network; });
}

Classification classify(const PointCloud& cloud, const Model& model,
                        const std::vector<int>& scales) {
  if (!model.gated()) return classify_ungated(cloud, model, scales);
  model.check();
  const std::vector<int> chosen_scales = scales_for(model, scales);
  const std::vector<std::uint8_t> reads = whole_cloud_reads(model, cloud.size());
  std::vector<GateDecision> decisions;
  Classification result = run_network(
      cloud, model, chosen_scales,
      [&](const geometry::NeighbourhoodSearch& search, SearchFindings& findings) {
        // Each gate passes the cloud on or keeps it for its own network.
        const Model* network = &model;
        while (network->gated()) {
          decisions.push_back(
              tally_of(cloud, *network, search, reads, chosen_scales, &findings).decision());
          if (!decisions.back().gate_network_answered) break;
          network = network->gate_network.get();
        }
        return network;
      });
  result.gates = std::move(decisions);
  return result;
}

Classification classify_features(const FeatureMatrix& features, const Model& model) {
  if (model.gated())
    throw Error("model", "gate",
                "a gated model chooses its network before the features: classify the cloud");
  model.check_features(features);
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
