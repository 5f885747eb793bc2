#include "reflectance/material_evaluation.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <set>
#include <utility>
#include <vector>

#include "core/error.h"
#include "core/parallel.h"
#include "denoise/metrics.h"
#include "io/image_io.h"
#include "render/sensor.h"

namespace glint::reflectance {
namespace {

namespace fs = std::filesystem;

// gt/<kind>/<frame name>.<extension> beside the frame's rgb/<frame name>.png.
std::string ground_truth_path(const io::RgbdSequence& sequence, std::size_t i,
                              const std::string& kind, const std::string& extension) {
  const fs::path colour = sequence.frames.at(i).colour_path;
  return (fs::path(sequence.folder) / "gt" / kind / colour.stem()).string() + extension;
}

ImageF read_checked(const std::string& path, int channels) {
  ImageF image = io::read_image(path);
  if (image.channels() != channels)
    throw Error(path, "",
                "expected " + std::to_string(channels) + " channels, found " +
                    std::to_string(image.channels()));
  return image;
}

ImageF srgb_encoded(const ImageF& linear) {
  ImageF encoded = linear;
  for (float& value : encoded.values()) value = render::linear_to_srgb(std::clamp(value, 0.f, 1.f));
  return encoded;
}

struct Box {
  int x0, y0, x1, y1;  // inclusive-exclusive
};

// The box's part of the image; with a mask, pixels outside it are zero.
ImageF crop(const ImageF& image, const Box& box, const ImageF* mask = nullptr) {
  ImageF out(box.x1 - box.x0, box.y1 - box.y0, image.channels());
  for (int c = 0; c < image.channels(); ++c)
    for (int y = box.y0; y < box.y1; ++y)
      for (int x = box.x0; x < box.x1; ++x)
        out.at(x - box.x0, y - box.y0, c) =
            !mask || mask->at(x, y, 0) >= 0.5f ? image.at(x, y, c) : 0.0f;
  return out;
}

// SSIM's 11x11 window reaches 5 pixels from its centre (denoise/metrics.h).
constexpr int kSsimRadius = 5;

Box grown(const Box& box, int margin, int width, int height) {
  return {std::max(box.x0 - margin, 0), std::max(box.y0 - margin, 0),
          std::min(box.x1 + margin, width), std::min(box.y1 + margin, height)};
}

// PSNR of a mean squared error, peak 1, capped at 100 dB.
double capped_psnr(double mse) { return -10.0 * std::log10(std::max(mse, 1e-10)); }

Scores score(const ImageF& truth, const ImageF& estimate, const ImageF& mask, const Box& box) {
  double absolute = 0, squared = 0;
  std::size_t count = 0;
  for (int y = box.y0; y < box.y1; ++y)
    for (int x = box.x0; x < box.x1; ++x) {
      if (mask.at(x, y, 0) < 0.5f) continue;
      for (int c = 0; c < truth.channels(); ++c) {
        const double d = double(estimate.at(x, y, c)) - truth.at(x, y, c);
        absolute += std::fabs(d);
        squared += d * d;
        ++count;
      }
    }
  Scores s;
  s.l1 = absolute / count;
  const double mse = squared / count;
  s.rmse = std::sqrt(mse);
  s.psnr = capped_psnr(mse);
  // SSIM over the object's bounding box (the masked mean is the same; it is far cheaper).
  const ImageF box_mask = crop(mask, box);
  s.ssim = denoise::ssim(crop(truth, box), crop(estimate, box), &box_mask);

  // Whole frame, the object alone (zero elsewhere in both images): outside the object the
  // error is zero, and every SSIM window more than its radius away from the object sees two
  // equal zero patches (SSIM 1). So only the object's box grown by twice the radius is
  // computed: windows within one radius of the box then stay inside the crop, where
  // denoise::ssim's border (windows cut and renormalised) would otherwise change their means.
  const double frame_pixels = double(truth.width()) * truth.height();
  s.psnr_frame = capped_psnr(squared / (frame_pixels * truth.channels()));
  const Box around = grown(box, 2 * kSsimRadius, truth.width(), truth.height());
  const double around_pixels = double(around.x1 - around.x0) * (around.y1 - around.y0);
  const ImageF truth_alone = crop(truth, around, &mask);
  const ImageF estimate_alone = crop(estimate, around, &mask);
  const double ssim_around = denoise::ssim(truth_alone, estimate_alone);
  s.ssim_frame = (ssim_around * around_pixels + (frame_pixels - around_pixels)) / frame_pixels;
  const ImageF around_mask = crop(mask, around);
  s.ssim_object = denoise::ssim(truth_alone, estimate_alone, &around_mask);
  return s;
}

double masked_mean(const ImageF& image, int channel, const ImageF& mask, const Box& box) {
  double sum = 0;
  std::size_t count = 0;
  for (int y = box.y0; y < box.y1; ++y)
    for (int x = box.x0; x < box.x1; ++x)
      if (mask.at(x, y, 0) >= 0.5f) sum += image.at(x, y, channel), ++count;
  return count ? sum / count : NAN;
}

Scores mean_of(const std::vector<Scores>& all) {
  Scores mean;
  for (const Scores& s : all) {
    mean.l1 += s.l1 / all.size();
    mean.rmse += s.rmse / all.size();
    mean.psnr += s.psnr / all.size();
    mean.ssim += s.ssim / all.size();
    mean.psnr_frame += s.psnr_frame / all.size();
    mean.ssim_frame += s.ssim_frame / all.size();
    mean.ssim_object += s.ssim_object / all.size();
  }
  return mean;
}

nlohmann::json scores_json(const Scores& s) {
  return {{"l1", s.l1},
          {"rmse", s.rmse},
          {"psnr", s.psnr},
          {"ssim", s.ssim},
          {"psnr_frame", s.psnr_frame},
          {"ssim_frame", s.ssim_frame},
          {"ssim_object", s.ssim_object}};
}

}  // namespace

bool has_ground_truth_maps(const io::RgbdSequence& sequence) {
  return sequence.format == "glint" && !sequence.frames.empty() &&
         fs::exists(ground_truth_path(sequence, 0, "segment", ".png"));
}

Image<std::int32_t> read_ground_truth_segments(const io::RgbdSequence& sequence, std::size_t i) {
  const ImageF values = read_checked(ground_truth_path(sequence, i, "segment", ".png"), 1);
  Image<std::int32_t> ids(values.width(), values.height(), 1);
  for (std::size_t p = 0; p < values.pixel_count(); ++p)
    ids.plane(0)[p] = std::int32_t(std::lround(values.plane(0)[p] * 65535.0f));
  return ids;
}

ImageF read_ground_truth_map(const io::RgbdSequence& sequence, std::size_t i,
                             const std::string& kind, int channels) {
  return read_checked(ground_truth_path(sequence, i, kind, ".exr"), channels);
}

GroundTruthMaps read_ground_truth_maps(const io::RgbdSequence& sequence, std::size_t i) {
  GroundTruthMaps maps;
  maps.kd = read_ground_truth_map(sequence, i, "kd", 3);
  maps.ks = read_ground_truth_map(sequence, i, "ks", 3);
  maps.alpha = read_ground_truth_map(sequence, i, "alpha", 1);
  maps.segment = read_ground_truth_segments(sequence, i);
  return maps;
}

const char* quantity_name(Quantity quantity) {
  switch (quantity) {
    case Quantity::kd:
      return "kd";
    case Quantity::kd_refined:
      return "kd_ref";
    case Quantity::ks:
      return "ks";
    case Quantity::alpha:
      return "alpha";
    case Quantity::rgb:
      return "rgb";
    case Quantity::rgb_refined:
      return "rgb_ref";
  }
  return "?";
}

void MaterialEvaluation::add_frame(int frame, const MaterialMaps& estimate,
                                   const GroundTruthMaps& truth, const ImageF& input_rgb) {
  const int width = truth.segment.width(), height = truth.segment.height();
  const auto same_size = [&](const auto& image) {
    return image.width() == width && image.height() == height;
  };
  if (!same_size(estimate.covered) || !same_size(truth.kd) || !same_size(input_rgb))
    throw Error("material evaluation", "frame " + std::to_string(frame),
                "estimate, ground truth and input differ in size");
  const ImageF input_srgb = srgb_encoded(input_rgb);
  const ImageF rgb = srgb_encoded(estimate.rgb), rgb_refined = srgb_encoded(estimate.rgb_refined);

  std::set<int> objects(truth.segment.values().begin(), truth.segment.values().end());
  objects.erase(0);
  // The objects with enough covered pixels, each with its mask and bounding box.
  struct ObjectView {
    int object;
    ImageF mask;
    Box box;
    int covered, pixels;
  };
  std::vector<ObjectView> views;
  for (int object : objects) {
    ObjectView entry{object, ImageF(width, height, 1), Box{width, height, 0, 0}, 0, 0};
    for (int y = 0; y < height; ++y)
      for (int x = 0; x < width; ++x) {
        const bool mine = truth.segment.at(x, y, 0) == object;
        entry.pixels += mine;
        const bool covered = mine && estimate.covered.at(x, y, 0) > 0.5f;
        entry.mask.at(x, y, 0) = covered ? 1.0f : 0.0f;
        if (!covered) continue;
        ++entry.covered;
        entry.box = {std::min(entry.box.x0, x), std::min(entry.box.y0, y),
                     std::max(entry.box.x1, x + 1), std::max(entry.box.y1, y + 1)};
      }
    if (entry.covered >= min_pixels_) views.push_back(std::move(entry));
  }
  // (truth, estimate) per quantity, in kQuantities' order; every object and quantity is scored
  // in parallel (the SSIMs are most of an evaluated frame's time).
  const std::array<std::pair<const ImageF*, const ImageF*>, kQuantities.size()> pairs{{
      {&truth.kd, &estimate.kd},
      {&truth.kd, &estimate.kd_refined},
      {&truth.ks, &estimate.ks},
      {&truth.alpha, &estimate.alpha},
      {&input_srgb, &rgb},
      {&input_srgb, &rgb_refined},
  }};
  std::vector<Scores> results(views.size() * pairs.size());
  parallel_for(results.size(), [&](std::size_t i) {
    const ObjectView& entry = views[i / pairs.size()];
    const auto& [true_image, estimated] = pairs[i % pairs.size()];
    results[i] = score(*true_image, *estimated, entry.mask, entry.box);
  });
  for (std::size_t k = 0; k < views.size(); ++k) {
    const int object = views[k].object;
    const ImageF& mask = views[k].mask;
    const Box& box = views[k].box;
    auto& scores = frames_[object];
    for (std::size_t q = 0; q < pairs.size(); ++q)
      scores[kQuantities[q]].push_back(results[k * pairs.size() + q]);

    Sample sample;
    sample.frame = frame;
    sample.kd = masked_mean(estimate.kd, 0, mask, box);
    sample.kd_refined = masked_mean(estimate.kd_refined, 0, mask, box);
    sample.ks = masked_mean(estimate.ks, 0, mask, box);
    sample.alpha = masked_mean(estimate.alpha, 0, mask, box);
    sample.rgb = masked_mean(rgb, 0, mask, box);
    sample.rgb_refined = masked_mean(rgb_refined, 0, mask, box);
    sample.true_kd = masked_mean(truth.kd, 0, mask, box);
    sample.true_ks = masked_mean(truth.ks, 0, mask, box);
    sample.true_alpha = masked_mean(truth.alpha, 0, mask, box);
    sample.true_rgb = masked_mean(input_srgb, 0, mask, box);
    sample.coverage = double(views[k].covered) / views[k].pixels;
    series_[object].push_back(sample);
  }
}

std::map<int, std::map<Quantity, Scores>> MaterialEvaluation::table() const {
  std::map<int, std::map<Quantity, Scores>> table;
  for (const auto& [object, quantities] : frames_)
    for (const auto& [quantity, all] : quantities) table[object][quantity] = mean_of(all);
  return table;
}

std::map<Quantity, Scores> MaterialEvaluation::average() const {
  std::map<Quantity, std::vector<Scores>> per_object;
  for (const auto& [object, quantities] : table())
    for (const auto& [quantity, scores] : quantities) per_object[quantity].push_back(scores);
  std::map<Quantity, Scores> average;
  for (const auto& [quantity, all] : per_object) average[quantity] = mean_of(all);
  return average;
}

nlohmann::json MaterialEvaluation::to_json() const {
  nlohmann::json objects = nlohmann::json::object();
  for (const auto& [object, quantities] : table()) {
    nlohmann::json entry;
    for (const auto& [quantity, scores] : quantities)
      entry[quantity_name(quantity)] = scores_json(scores);
    entry["frames"] = frames_.at(object).begin()->second.size();
    objects[std::to_string(object)] = entry;
  }
  nlohmann::json average_json;
  for (const auto& [quantity, scores] : average())
    average_json[quantity_name(quantity)] = scores_json(scores);
  nlohmann::json series = nlohmann::json::object();
  for (const auto& [object, samples] : series_) {
    nlohmann::json rows = nlohmann::json::array();
    for (const Sample& s : samples)
      rows.push_back({s.frame, s.kd, s.kd_refined, s.ks, s.alpha, s.rgb, s.rgb_refined, s.true_kd,
                      s.true_ks, s.true_alpha, s.true_rgb, s.coverage});
    series[std::to_string(object)] = rows;
  }
  return {{"objects", objects},
          {"average", average_json},
          {"series_columns",
           {"frame", "kd_r", "kd_ref_r", "ks_r", "alpha", "rgb_r", "rgb_ref_r", "true_kd_r",
            "true_ks_r", "true_alpha", "true_rgb_r", "coverage"}},
          {"series", series}};
}

}  // namespace glint::reflectance
