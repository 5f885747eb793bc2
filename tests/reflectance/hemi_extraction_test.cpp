// HemiCNN training data from rendered sequences, end to end through `glint hemicnn dataset`:
// the pipeline's own observation collection turns each training sequence into hemi-images of
// its object, labelled with the sequence's material.
#include <gtest/gtest.h>

#include "reflectance/hemi_dataset.h"
#include "support/cli_fixture.h"

namespace glint {
namespace {

class HemiDatasetCli : public CliTest {};

TEST_F(HemiDatasetCli, TurnsATrainingSetIntoLabelledHemiImagesInBothProjections) {
  // Spheres and boxes need no data folder.
  ASSERT_EQ(
      glint("synth training -o " + path("train") + " --sequences 2 --frames 16 --shapes sphere,box")
          .exit_code,
      0);
  const CommandResult result =
      glint("hemicnn dataset " + path("train") + " -o " + path("hemi") + " --max-images 60");
  ASSERT_EQ(result.exit_code, 0) << result.output;
  for (const char* projection : {"parabolic", "orthographic"}) {
    const reflectance::HemiDataset dataset =
        reflectance::read_hemi_dataset(path("hemi") + "/" + projection);
    ASSERT_EQ(dataset.sequences.size(), 2u) << projection;
    for (const auto& sequence : dataset.sequences) {
      EXPECT_GE(sequence.images, 25);
      EXPECT_LE(sequence.images, 60);
      float brightest = 0;
      for (float v : sequence.values) brightest = std::max(brightest, v);
      EXPECT_GT(brightest, 0.05f) << "observations carry the rendered radiance";
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
