// HemiCNN training data from rendered sequences, end to end through `glint hemicnn dataset`:
// the pipeline's own observation collection turns each training sequence into hemi-images of
// its object, labelled with the sequence's material.
#include <gtest/gtest.h>

#include <algorithm>
#include <vector>

#include "reflectance/hemi_dataset.h"
#include "support/cli_fixture.h"

namespace glint {
namespace {

class HemiDatasetCli : public CliTest {};

TEST_F(HemiDatasetCli, TurnsATrainingSetIntoLabelledHemiImagesOfEveryKind) {
  // Spheres and boxes need no data folder.
  ASSERT_EQ(
      glint("synth training -o " + path("train") + " --sequences 2 --frames 16 --shapes sphere,box")
          .exit_code,
      0);
  const CommandResult result =
      glint("hemicnn dataset " + path("train") + " -o " + path("hemi") + " --max-images 60");
  ASSERT_EQ(result.exit_code, 0) << result.output;
  for (const char* kind :
       {"parabolic", "orthographic", "parabolic-reflectance", "orthographic-reflectance"}) {
    const reflectance::HemiDataset dataset =
        reflectance::read_hemi_dataset(path("hemi") + "/" + kind);
    EXPECT_EQ(dataset.input, std::string(kind).ends_with("reflectance")
                                 ? reflectance::HemiInput::reflectance
                                 : reflectance::HemiInput::radiance);
    ASSERT_EQ(dataset.sequences.size(), 2u) << kind;
    for (const auto& sequence : dataset.sequences) {
      EXPECT_GE(sequence.images, 25);
      EXPECT_LE(sequence.images, 60);
      float brightest = 0;
      for (float v : sequence.values) brightest = std::max(brightest, v);
      EXPECT_GT(brightest, 0.05f) << "observations carry the rendered radiance";
      if (dataset.input == reflectance::HemiInput::radiance) continue;
      // Reflectance: most pixels show the diffuse albedo (the lobe rises above it in a few).
      for (int c = 0; c < 3; ++c) {
        std::vector<float> channel;
        for (int k = 0; k < sequence.images; ++k)
          for (int p = 0; p < 225; ++p)
            if (const float v = sequence.image(k, 15)[c * 225 + p]; v > 0) channel.push_back(v);
        std::nth_element(channel.begin(), channel.begin() + channel.size() / 2, channel.end());
        EXPECT_NEAR(channel[channel.size() / 2], sequence.material.kd[c],
                    0.005f + 0.03f * sequence.material.kd[c])
            << kind << " channel " << c;
      }
    }
  }
}

TEST_F(HemiDatasetCli, AFolderWithoutSequencesIsAnError) {
  const CommandResult result = glint("hemicnn dataset " + path(".") + " -o " + path("hemi"));
  EXPECT_NE(result.exit_code, 0);
  EXPECT_NE(result.output.find("seq_"), std::string::npos) << result.output;
}

}  // namespace
}  // namespace glint
