// The renderer's indirect light (Scene::bounces > 0): the furnace (a point light inside a
// closed diffuse sphere, radiance and indirect irradiance in closed form for every bounce
// count), zero bounces and
// convex scenes identical to the direct image, light proxies not counted twice, determinism.
#include <gtest/gtest.h>

#include <cmath>

#include "core/parallel.h"
#include "io/image_io.h"
#include "render/renderer.h"
#include "scene_fixtures.h"

namespace glint::render {
namespace {

using test::make_object;
using test::plane_scene;

// The inside of a diffuse sphere of radius 1 (albedo rho) with a point light at its centre,
// seen from inside. Direct light is I / R^2 at normal incidence everywhere, so every wall point
// leaves L0 = rho / pi * I / R^2; a closed enclosure of uniform radiance L irradiates every
// point with pi L, so each bounce multiplies by rho:  L_N = L0 * sum_{k=0..N} rho^k.
Scene furnace_scene(float rho, int bounces, double proxy_radius_m) {
  Scene scene;
  scene.objects.push_back(make_object(1, ShapeKind::sphere, {1, 1, 1}, {0, 0, 0},
                                      WardMaterial{{rho, rho, rho}, {0, 0, 0}, 0.1f}));
  PointLight light;
  light.position = {0, 0, 0};
  light.intensity = {2.0f, 1.0f, 0.5f};
  light.proxy_radius_m = proxy_radius_m;
  scene.lights.push_back(light);
  scene.camera.intrinsics = {32, 24, 20.0, 20.0, 15.5, 11.5};
  scene.trajectory = {look_at({0.2, 0.1, 0.3}, {0.0, 0.0, -1.0})};
  scene.bounces = bounces;
  scene.indirect_samples = 4;
  return scene;
}

TEST(PathTracer, FurnaceSphereMatchesTheClosedFormForEveryBounceCount) {
  for (const float rho : {0.5f, 0.8f}) {
    for (const int bounces : {0, 1, 2, 3, 6}) {
      for (const double proxy_radius_m : {0.0, 0.05}) {
        const Scene scene = furnace_scene(rho, bounces, proxy_radius_m);
        const FrameBuffers frame = Renderer(scene).render(scene.trajectory[0], 0);
        double series = 0;
        for (int k = 0; k <= bounces; ++k) series += std::pow(double(rho), k);
        int walls = 0;
        for (std::size_t i = 0; i < frame.radiance.pixel_count(); ++i) {
          if (frame.segment.plane(0)[i] != 1) continue;  // the proxy in view
          ++walls;
          for (int c = 0; c < 3; ++c) {
            const double expected = rho / M_PI * scene.lights[0].intensity[c] * series;
            // Cosine sampling of a diffuse furnace has zero variance: every path carries
            // exactly rho per bounce, so only float rounding remains (1e-4 relative).
            ASSERT_NEAR(frame.radiance.plane(c)[i], expected, 1e-4 * expected)
                << "rho " << rho << " bounces " << bounces << " proxy " << proxy_radius_m
                << " pixel " << i << " channel " << c;
          }
        }
        EXPECT_GT(walls, int(frame.radiance.pixel_count()) / 2);
      }
    }
  }
}

// The irradiance of the bounced light at a point inside the furnace, facing a wall: with N
// bounces each wall point leaves L0 * sum_{k<N} rho^k towards it (its direct light and N - 1
// bounces), uniform over the hemisphere, so E = pi * that = rho * I * sum_{k<N} rho^k, zero
// for N = 0. Every path carries exactly that (zero variance), as in the pixels above.
TEST(PathTracer, IndirectIrradianceInTheFurnaceIsTheClosedForm) {
  for (const float rho : {0.5f, 0.8f}) {
    for (const int bounces : {0, 1, 3}) {
      const Scene scene = furnace_scene(rho, bounces, 0.05);
      const Eigen::Vector3f irradiance =
          Renderer(scene).indirect_irradiance({0.1f, 0.0f, -0.9f}, {0, 0, 1}, 16, 7);
      double series = 0;
      for (int k = 0; k < bounces; ++k) series += std::pow(double(rho), k);
      for (int c = 0; c < 3; ++c) {
        const double expected = rho * scene.lights[0].intensity[c] * series;
        EXPECT_NEAR(irradiance[c], expected, 1e-4 * expected + 1e-7)
            << "rho " << rho << " bounces " << bounces << " channel " << c;
      }
    }
  }
}

// Two boxes on a glossy floor under one light: surfaces that see each other.
Scene concave_scene() {
  Scene scene = plane_scene();
  scene.objects.push_back(make_object(2, ShapeKind::box, {0.5, 0.6, 0.5}, {-0.2, 0.3, -0.3},
                                      WardMaterial{{0.7f, 0.6f, 0.5f}, {0.2f, 0.2f, 0.2f}, 0.1f}));
  scene.objects.push_back(make_object(3, ShapeKind::box, {0.4, 0.3, 0.4}, {0.5, 0.15, 0.3},
                                      WardMaterial{{0.1f, 0.5f, 0.2f}, {0.0f, 0.0f, 0.0f}, 0.3f}));
  return scene;
}

TEST(PathTracer, BouncesOnlyAddLightAndKeepTheGroundTruth) {
  Scene scene = concave_scene();
  const Pose& pose = scene.trajectory[0];
  const FrameBuffers direct = Renderer(scene).render(pose, 0);
  scene.bounces = 2;
  scene.indirect_samples = 8;
  const FrameBuffers bounced = Renderer(scene).render(pose, 0);
  EXPECT_EQ(bounced.depth.values(), direct.depth.values());
  EXPECT_EQ(bounced.normal.values(), direct.normal.values());
  EXPECT_EQ(bounced.segment.values(), direct.segment.values());
  EXPECT_EQ(bounced.kd.values(), direct.kd.values());
  EXPECT_EQ(bounced.ks.values(), direct.ks.values());
  EXPECT_EQ(bounced.alpha.values(), direct.alpha.values());
  for (std::size_t i = 0; i < direct.radiance.values().size(); ++i)
    ASSERT_GE(bounced.radiance.values()[i], direct.radiance.values()[i]) << "value " << i;
  // The boxes' sides see the lit floor: nearly all of their pixels gain light (a pixel whose 8
  // paths all leave towards the sky keeps its direct value).
  int sides = 0, brighter = 0;
  for (std::size_t i = 0; i < direct.radiance.pixel_count(); ++i) {
    if (direct.segment.plane(0)[i] < 2 || std::abs(direct.normal.plane(1)[i]) > 0.5f) continue;
    ++sides;
    brighter += bounced.radiance.plane(1)[i] > direct.radiance.plane(1)[i];
  }
  ASSERT_GT(sides, 50);
  EXPECT_GT(brighter, 0.9 * sides);
}

// A lone plane cannot light itself: every bounce ray leaves the scene, and the constant
// environment it would meet is counted by the direct part only, so the image is the direct one
// bit for bit.
TEST(PathTracer, ConvexSceneUnderLightsAndEnvironmentIsTheDirectImageExactly) {
  test::TemporaryFolder folder;
  const std::string map = folder.path("grey.exr");
  io::write_image(map, ImageF(32, 16, 3, 0.3f));
  Scene scene = plane_scene();
  scene.environment = Environment{map, 1.0f, 0.0f, 16};
  const Pose& pose = scene.trajectory[0];
  const FrameBuffers direct = Renderer(scene).render(pose, 3);
  scene.bounces = 3;
  const FrameBuffers bounced = Renderer(scene).render(pose, 3);
  EXPECT_EQ(bounced.radiance.values(), direct.radiance.values());
}

TEST(PathTracer, DeterministicPerSeedAndFrameWhateverTheThreadCount) {
  Scene scene = concave_scene();
  scene.bounces = 2;
  scene.indirect_samples = 4;
  const Pose& pose = scene.trajectory[0];
  const Renderer renderer(scene);
  const FrameBuffers frame = renderer.render(pose, 0);
  {
    const auto single_thread = limit_threads(1);
    EXPECT_EQ(renderer.render(pose, 0).radiance.values(), frame.radiance.values());
  }
  EXPECT_EQ(renderer.render(pose, 0).radiance.values(), frame.radiance.values());
  EXPECT_NE(renderer.render(pose, 1).radiance.values(), frame.radiance.values());
  scene.seed = 2;
  EXPECT_NE(Renderer(scene).render(pose, 0).radiance.values(), frame.radiance.values());
}

// More paths per pixel converge to the same image: the mean over the surface of 4 and of 64
// paths agree within the 4-path estimate's noise, and the per-pixel spread shrinks.
TEST(PathTracer, MorePathsConvergeToTheSameMean) {
  Scene scene = concave_scene();
  scene.bounces = 2;
  const Pose& pose = scene.trajectory[0];
  scene.indirect_samples = 64;
  const FrameBuffers reference = Renderer(scene).render(pose, 0);
  scene.bounces = 0;
  const FrameBuffers direct = Renderer(scene).render(pose, 0);
  scene.bounces = 2;
  scene.indirect_samples = 4;
  const FrameBuffers few = Renderer(scene).render(pose, 0);
  double indirect_reference = 0, indirect_few = 0;
  for (std::size_t i = 0; i < direct.radiance.values().size(); ++i) {
    indirect_reference += reference.radiance.values()[i] - direct.radiance.values()[i];
    indirect_few += few.radiance.values()[i] - direct.radiance.values()[i];
  }
  ASSERT_GT(indirect_reference, 0);
  EXPECT_NEAR(indirect_few / indirect_reference, 1.0, 0.05);
}

}  // namespace
}  // namespace glint::render
