// glint hemicnn probe: a reflectance HemiCNN's answer for Lambertian surfaces of given albedos.
// A Lambertian surface's reflectance hemi-images (reflectance/hemi_image.h) show its albedo in
// every pixel whatever the lights, so 25 constant images are the input a matte voxel set gives
// the network in the pipeline; the kd that comes back shows the network's colour calibration in
// seconds, without rendering or reconstructing a scene.
#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <memory>
#include <sstream>

#include "cli_support.h"
#include "commands.h"
#include "core/error.h"
#include "io/codec.h"
#include "io/json_report.h"
#include "reflectance/hemicnn.h"
#include "reflectance/specular_estimation.h"
#include "render/perceptual.h"

namespace glint::app {
namespace {

// The default probes: a grey ramp, then the evaluation scenes' kinds of colour (a light wall,
// a saturated yellow, a dark green, a blue-grey).
std::vector<Eigen::Vector3f> default_albedos() {
  std::vector<Eigen::Vector3f> albedos;
  for (float grey : {0.05f, 0.1f, 0.2f, 0.3f, 0.4f, 0.5f, 0.6f, 0.7f, 0.8f, 0.9f})
    albedos.push_back(Eigen::Vector3f::Constant(grey));
  albedos.insert(
      albedos.end(),
      {{0.69f, 0.67f, 0.61f}, {0.75f, 0.55f, 0.04f}, {0.05f, 0.2f, 0.08f}, {0.3f, 0.35f, 0.4f}});
  return albedos;
}

struct ProbeOptions {
  std::string model;
  std::vector<std::string> albedos;
  std::string report;
};

// "v" (a grey) or "r,g,b", each in [0, 1].
Eigen::Vector3f parse_albedo(const std::string& text) {
  std::vector<float> values;
  std::stringstream stream(text);
  std::string item;
  while (std::getline(stream, item, ',')) {
    double value = NAN;
    if (!io::parse_number(item, value) || !(value >= 0.0 && value <= 1.0))
      throw Error("--kd", text, "expected a grey or r,g,b, each a number in [0, 1]");
    values.push_back(float(value));
  }
  if (values.size() == 1) return Eigen::Vector3f::Constant(values[0]);
  if (values.size() != 3) throw Error("--kd", text, "expected a grey or r,g,b");
  return {values[0], values[1], values[2]};
}

void run_probe(const ProbeOptions& options) {
  const reflectance::HemiCnn model = reflectance::HemiCnn::load(options.model);
  if (model.input() != reflectance::HemiInput::reflectance)
    throw Error(options.model, "input",
                "a radiance model: its input for a Lambertian surface depends on the lights; "
                "probe takes models of reflectance hemi-images");
  std::vector<Eigen::Vector3f> albedos;
  for (const std::string& text : options.albedos) albedos.push_back(parse_albedo(text));
  if (albedos.empty()) albedos = default_albedos();

  // As many images as the pipeline's specular estimate hands the network per segment.
  const int set_size = reflectance::SpecularParams{}.voxels_per_estimate;
  const std::size_t floats = model.image_floats();
  const std::size_t pixels = floats / 3;
  std::vector<float> images(set_size * floats);
  fmt::print(
      "HemiCNN {} ({}, reflectance): {} constant hemi-images per albedo, what a\n"
      "Lambertian surface shows under any lights\n"
      "  albedo               -> kd                   kd/albedo  ks                     "
      "alpha\n",
      options.model, reflectance::hemi_projection_name(model.projection()), set_size);
  nlohmann::json probes = nlohmann::json::array();
  double kd_error = 0;
  for (const Eigen::Vector3f& albedo : albedos) {
    for (int i = 0; i < set_size; ++i)
      for (int c = 0; c < 3; ++c)
        std::fill_n(images.begin() + std::ptrdiff_t(i * floats + c * pixels), pixels, albedo[c]);
    const render::WardMaterial ward =
        render::from_perceptual(model.predict(images.data(), set_size));
    // Ratio of the mean channels: how much brighter or darker the network makes the surface.
    const float ratio = albedo.mean() > 0 ? ward.kd.mean() / albedo.mean() : NAN;
    kd_error += (ward.kd - albedo).cwiseAbs().mean() / double(albedos.size());
    fmt::print(
        "  {:.2f} {:.2f} {:.2f}       -> {:.3f} {:.3f} {:.3f}    {:6.2f}     {:.3f} {:.3f} "
        "{:.3f}    {:.3f}\n",
        albedo.x(), albedo.y(), albedo.z(), ward.kd.x(), ward.kd.y(), ward.kd.z(), ratio,
        ward.ks.x(), ward.ks.y(), ward.ks.z(), ward.alpha);
    probes.push_back({{"albedo", io::vector_json(albedo)},
                      {"kd", io::vector_json(ward.kd)},
                      {"ks", io::vector_json(ward.ks)},
                      {"alpha", ward.alpha}});
  }
  fmt::print(
      "  mean absolute kd error over the {} albedos: {:.4f} (the right answer for each:\n"
      "  kd = albedo, ks = 0)\n",
      albedos.size(), kd_error);
  if (!options.report.empty()) {
    io::write_json(options.report, {{"command", "hemicnn probe"},
                                    {"command_line", command_line()},
                                    {"model", options.model},
                                    {"set_size", set_size},
                                    {"kd_mean_absolute_error", kd_error},
                                    {"probes", probes}});
    fmt::print("report -> {}\n", options.report);
  }
}

}  // namespace

void register_hemicnn_probe(CLI::App& hemicnn) {
  auto options = std::make_shared<ProbeOptions>();
  CLI::App* command = hemicnn.add_subcommand(
      "probe", "A reflectance HemiCNN's kd, ks and alpha for Lambertian surfaces of given albedos");
  command->footer(
      "Every pixel of a Lambertian surface's reflectance hemi-images is its albedo, whatever\n"
      "the lights; so 25 constant images are what a matte segment gives the network in the\n"
      "pipeline. The kd that comes back shows how the network maps colours (e.g. whether it\n"
      "darkens light greys) in seconds, without rendering a scene. Default albedos: a grey\n"
      "ramp 0.05-0.9 and four colours of the evaluation scenes.\n"
      "Examples:\n"
      "  glint hemicnn probe --model models/hemicnn.json\n"
      "  glint hemicnn probe --model models/hemicnn.json --kd 0.5 --kd 0.8,0.2,0.1 --report "
      "p.json");
  command->add_option("--model", options->model, "HemiCNN model file of reflectance input")
      ->required();
  command->add_option("--kd", options->albedos,
                      "Albedo to probe: a grey (0.5) or linear r,g,b (0.8,0.2,0.1), each in "
                      "[0, 1]; repeatable (default: the ramp and colours above)");
  command->add_option("--report", options->report, "Write the answers as JSON")->check(kOutputFile);
  command->callback([options] { run_probe(*options); });
}

}  // namespace glint::app
