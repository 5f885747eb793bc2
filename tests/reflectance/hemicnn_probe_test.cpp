// `glint hemicnn probe`: a reflectance HemiCNN's answer for Lambertian surfaces, end to end.
#include <gtest/gtest.h>

#include <fstream>
#include <nlohmann/json.hpp>

#include "reflectance/hemicnn.h"
#include "render/perceptual.h"
#include "support/cli_fixture.h"

namespace glint {
namespace {

class HemiCnnProbeCli : public CliTest {
 protected:
  // A network with zero weights answers its target mean for every input.
  std::string write_constant_model(reflectance::HemiInput input) const {
    reflectance::HemiCnnConfig config;
    config.input = input;
    reflectance::HemiCnn model(config);
    const float mean[reflectance::HemiCnn::kTargets] = {60.0f, 10.0f, -20.0f, 0.05f,
                                                        0.06f, 0.07f, 0.9f};
    std::copy_n(mean, reflectance::HemiCnn::kTargets, model.target_mean);
    const std::string file =
        path(input == reflectance::HemiInput::reflectance ? "reflectance.json" : "radiance.json");
    model.save(file);
    return file;
  }
};

TEST_F(HemiCnnProbeCli, AnswersEachAlbedoWithTheNetworksWardParameters) {
  const std::string model = write_constant_model(reflectance::HemiInput::reflectance);
  const CommandResult result = glint("hemicnn probe --model " + model +
                                     " --kd 0.5 --kd 0.8,0.2,0.1 --report " + path("probe.json"));
  ASSERT_EQ(result.exit_code, 0) << result.output;
  const nlohmann::json report = nlohmann::json::parse(std::ifstream(path("probe.json")));
  ASSERT_EQ(report["probes"].size(), 2u);
  EXPECT_EQ(report["probes"][0]["albedo"], nlohmann::json({0.5, 0.5, 0.5}));
  EXPECT_NEAR(report["probes"][1]["albedo"][0].get<double>(), 0.8, 1e-6);

  const reflectance::HemiCnn network = reflectance::HemiCnn::load(model);
  const render::WardMaterial expected =
      render::from_perceptual(reflectance::perceptual_from_outputs(network.target_mean));
  double error = 0;
  for (const auto& probe : report["probes"]) {
    for (int c = 0; c < 3; ++c) {
      EXPECT_NEAR(probe["kd"][c].get<double>(), expected.kd[c], 1e-5);
      EXPECT_NEAR(probe["ks"][c].get<double>(), expected.ks[c], 1e-5);
      error += std::abs(expected.kd[c] - probe["albedo"][c].get<double>()) / 6;
    }
    EXPECT_NEAR(probe["alpha"].get<double>(), expected.alpha, 1e-5);
  }
  EXPECT_NEAR(report["kd_mean_absolute_error"].get<double>(), error, 1e-5);
}

TEST_F(HemiCnnProbeCli, RefusesRadianceModelsAndBadAlbedos) {
  const CommandResult radiance =
      glint("hemicnn probe --model " + write_constant_model(reflectance::HemiInput::radiance));
  EXPECT_NE(radiance.exit_code, 0);
  EXPECT_NE(radiance.output.find("radiance model"), std::string::npos) << radiance.output;

  const std::string model = write_constant_model(reflectance::HemiInput::reflectance);
  for (const char* bad : {"1.5", "0.5,x,0.2", "0.5,0.2", "nan", "-0.1"}) {
    const CommandResult result = glint("hemicnn probe --model " + model + " --kd " + bad);
    EXPECT_NE(result.exit_code, 0) << bad;
    EXPECT_NE(result.output.find("--kd"), std::string::npos) << bad << ": " << result.output;
  }
}

}  // namespace
}  // namespace glint
