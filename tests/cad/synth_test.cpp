// The CAD-kernel generator: deterministic per seed (also when parts are made on several threads
// at once), every recipe and sampling produces a labelled cloud, opened parts have boundaries.
#include "cad/synth.h"

#include <gtest/gtest.h>

#include <Standard_Version.hxx>
#include <cstring>
#include <thread>
#include <vector>

namespace glint::cad {
namespace {

CadSynthParams small_params(std::uint64_t seed) {
  CadSynthParams params;
  params.part.seed = seed;
  params.min_points = 2000;
  params.max_points = 3000;
  return params;
}

TEST(CadSynth, SameSeedGivesTheSameCloudEverySampling) {
  for (Sampling sampling : {Sampling::vertices, Sampling::uniform, Sampling::scan}) {
    CadSynthParams params = small_params(21);
    params.samplings = {sampling};
    params.noise_levels = {0.5};
    params.outlier_probability = 1.0;
    const edges::SynthCloud a = synthesize_cad_cloud(params, 4);
    const edges::SynthCloud b = synthesize_cad_cloud(params, 4);
    ASSERT_EQ(a.cloud.size(), b.cloud.size());
    ASSERT_GT(a.cloud.size(), 100u);
    EXPECT_EQ(std::memcmp(a.cloud.x.data(), b.cloud.x.data(), a.cloud.size() * sizeof(float)), 0);
    EXPECT_EQ(std::memcmp(a.cloud.z.data(), b.cloud.z.data(), a.cloud.size() * sizeof(float)), 0);
    EXPECT_EQ(*a.cloud.get<std::uint8_t>("label"), *b.cloud.get<std::uint8_t>("label"));
    EXPECT_EQ(a.description.dump(), b.description.dump());
    EXPECT_EQ(a.description["sampling"], sampling_names()[static_cast<int>(sampling)]);

    params.part.seed = 22;
    const edges::SynthCloud c = synthesize_cad_cloud(params, 4);
    EXPECT_NE(a.description["part"].dump(), c.description["part"].dump());
  }
}

bool same_points(const edges::SynthCloud& a, const edges::SynthCloud& b) {
  const std::size_t bytes = a.cloud.size() * sizeof(float);
  return a.cloud.size() == b.cloud.size() &&
         std::memcmp(a.cloud.x.data(), b.cloud.x.data(), bytes) == 0 &&
         std::memcmp(a.cloud.y.data(), b.cloud.y.data(), bytes) == 0 &&
         std::memcmp(a.cloud.z.data(), b.cloud.z.data(), bytes) == 0;
}

// The kernel's fillet builder keeps global state (cad/part.cpp), so concurrent modelling must
// still give the serial parts. Parts 7, 16, 23 and 24 of seed 9001 are filleted and cut open:
// concurrent fillets corrupt them when modelling does not take turns.
TEST(CadSynth, PartsMadeOnConcurrentThreadsEqualTheSerialOnes) {
  CadSynthParams params = small_params(9001);
  params.part.plane_cut_probability = 1.0;
  params.samplings = {Sampling::vertices};
  params.max_points = 6000;
  const std::vector<std::uint64_t> indices{7, 16, 23, 24};
  std::vector<edges::SynthCloud> serial;
  for (std::uint64_t index : indices) serial.push_back(synthesize_cad_cloud(params, index));

  for (int round = 0; round < 2; ++round) {
    std::vector<edges::SynthCloud> concurrent(indices.size());
    std::vector<std::thread> threads;
    for (std::size_t i = 0; i < indices.size(); ++i)
      threads.emplace_back([&, i] { concurrent[i] = synthesize_cad_cloud(params, indices[i]); });
    for (std::thread& thread : threads) thread.join();
    for (std::size_t i = 0; i < indices.size(); ++i)
      EXPECT_TRUE(same_points(serial[i], concurrent[i])) << "part " << indices[i];
  }
}

TEST(CadSynth, EveryRecipeGivesAPartWithSharpEdges) {
  for (std::size_t r = 0; r < part_recipe_names().size(); ++r) {
    CadSynthParams params = small_params(5);
    params.part.recipes = {static_cast<PartRecipe>(r)};
    params.samplings = {Sampling::uniform};
    const edges::SynthCloud cloud = synthesize_cad_cloud(params, 1);
    EXPECT_EQ(cloud.description["part"]["recipe"], part_recipe_names()[r]);
    EXPECT_GT(cloud.description["labels"]["sharp-edge"].get<int>(), 0) << part_recipe_names()[r];
    EXPECT_EQ(cloud.description["labels"]["boundary"].get<int>(), 0);
  }
}

// Part 140 of seed 102 asks OpenCASCADE 7.6.3 for a fillet that crashes its fillet builder
// (SIGSEGV): the fillet is tried in a child process first, so the part is made without it.
TEST(CadSynth, AFilletThatCrashesTheKernelIsSkipped) {
  PartParams params;
  params.seed = 102;
  params.recipes = {PartRecipe::block, PartRecipe::plate, PartRecipe::extrusion,
                    PartRecipe::turned};
  params.plane_cut_probability = 0.2;
  params.faces_removed_probability = 0.15;
  const Part part = random_part(params, 140);
  EXPECT_FALSE(part.shape.IsNull());
#if OCC_VERSION_HEX == 0x070603
  bool crash_recorded = false;
  for (const auto& skipped : part.recipe["skipped"])
    crash_recorded |= skipped["failed"].get<std::string>().starts_with("kernel crashed");
  EXPECT_TRUE(crash_recorded) << part.recipe.dump();
#endif
}

TEST(CadSynth, OpenedPartsHaveBoundariesAndTheSameRecipe) {
  CadSynthParams closed = small_params(8);
  closed.samplings = {Sampling::uniform};
  CadSynthParams cut = closed;
  cut.part.plane_cut_probability = 1.0;
  CadSynthParams removed = closed;
  removed.part.faces_removed_probability = 1.0;
  for (std::uint64_t index : {0, 1}) {
    const edges::SynthCloud a = synthesize_cad_cloud(closed, index);
    const edges::SynthCloud b = synthesize_cad_cloud(cut, index);
    const edges::SynthCloud c = synthesize_cad_cloud(removed, index);
    EXPECT_EQ(a.description["part"]["operations"], b.description["part"]["operations"]);
    EXPECT_EQ(b.description["part"]["opening"]["kind"], "plane_cut");
    EXPECT_GT(b.description["labels"]["boundary"].get<int>(), 0);
    EXPECT_EQ(c.description["part"]["opening"]["kind"], "faces_removed");
    EXPECT_GT(c.description["labels"]["boundary"].get<int>(), 0);
  }
}

}  // namespace
}  // namespace glint::cad
