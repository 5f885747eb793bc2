// The renderer against closed-form expectations: Ward radiance of a lit plane, depth that
// back-projects onto the true surface, exact shadows, light proxies, environment lighting.
#include <gtest/gtest.h>

#include <cmath>

#include "io/image_io.h"
#include "render/renderer.h"
#include "scene_fixtures.h"

namespace glint::render {
namespace {

using test::make_object;
using test::plane_scene;

// World ray of pixel (x, y): origin and direction with camera-space z = 1.
struct PixelRay {
  Eigen::Vector3d origin, direction;
};
PixelRay pixel_ray(const Scene& scene, const Pose& pose, int x, int y) {
  return {pose.translation(), pose.linear() * scene.camera.intrinsics.ray(x, y)};
}

// Radiance at a plane point under one point light (paper 1 eqs 1-4): I / r^2 f cos(theta_i).
Eigen::Vector3f analytic_plane_radiance(const Scene& scene, const Eigen::Vector3d& point,
                                        const Eigen::Vector3d& eye) {
  const PointLight& light = scene.lights[0];
  const Eigen::Vector3d to_light = light.position - point;
  const Eigen::Vector3f wi = to_light.normalized().cast<float>();
  const Eigen::Vector3f wo = (eye - point).normalized().cast<float>();
  const Eigen::Vector3f n(0, 1, 0);
  const float cos_i = n.dot(wi);
  return (light.intensity / float(to_light.squaredNorm()))
             .cwiseProduct(ward_brdf(scene.objects[0].material.ward, n, wi, wo)) *
         cos_i;
}

TEST(Renderer, PlaneUnderOnePointLightMatchesTheAnalyticWardRadiance) {
  const Scene scene = plane_scene();
  const Pose& pose = scene.trajectory[0];
  const FrameBuffers frame = Renderer(scene).render(pose, 0);
  int checked = 0;
  for (int y = 0; y < frame.radiance.height(); ++y) {
    for (int x = 0; x < frame.radiance.width(); ++x) {
      const PixelRay ray = pixel_ray(scene, pose, x, y);
      const double t = -ray.origin.y() / ray.direction.y();  // plane y = 0, t = z-depth
      const Eigen::Vector3d point = ray.origin + t * ray.direction;
      if (t <= 0 || std::abs(point.x()) > 1.99 || std::abs(point.z()) > 1.99) continue;
      const Eigen::Vector3f expected = analytic_plane_radiance(scene, point, ray.origin);
      for (int c = 0; c < 3; ++c) {
        // Float maths along the way: 1e-4 relative (plus 1e-7 absolute for dark pixels).
        ASSERT_NEAR(frame.radiance.at(x, y, c), expected[c], 1e-4 * expected[c] + 1e-7)
            << "pixel " << x << "," << y << " channel " << c;
        EXPECT_FLOAT_EQ(frame.kd.at(x, y, c), scene.objects[0].material.ward.kd[c]);
        EXPECT_FLOAT_EQ(frame.ks.at(x, y, c), scene.objects[0].material.ward.ks[c]);
      }
      EXPECT_NEAR(frame.depth.at(x, y, 0), t, 1e-4);
      EXPECT_FLOAT_EQ(frame.alpha.at(x, y, 0), 0.15f);
      EXPECT_EQ(frame.segment.at(x, y, 0), 1);
      EXPECT_NEAR(frame.normal.at(x, y, 1), 1.0f, 1e-6f);
      ++checked;
    }
  }
  EXPECT_GT(checked, 96 * 72 / 2);
}

// The camera-space point of every pixel with depth, in world coordinates.
template <class Check>
int for_each_back_projected(const Scene& scene, const FrameBuffers& frame, const Pose& pose,
                            Check&& check) {
  int count = 0;
  for (int y = 0; y < frame.depth.height(); ++y) {
    for (int x = 0; x < frame.depth.width(); ++x) {
      const float z = frame.depth.at(x, y, 0);
      if (z <= 0) continue;
      check(pose * scene.camera.intrinsics.back_project(x, y, z), x, y);
      ++count;
    }
  }
  return count;
}

TEST(Renderer, DepthBackProjectsOntoThePlane) {
  const Scene scene = plane_scene();
  const Pose& pose = scene.trajectory[0];
  const FrameBuffers frame = Renderer(scene).render(pose, 0);
  const int count = for_each_back_projected(
      scene, frame, pose,
      [](const Eigen::Vector3d& p, int, int) { ASSERT_NEAR(p.y(), 0.0, 1e-4); });
  EXPECT_GT(count, 1000);
}

TEST(Renderer, DepthBackProjectsOntoTheSphereAndNormalsAreExact) {
  Scene scene = plane_scene();
  const Eigen::Vector3d centre(0.1, 0.6, -0.1);
  scene.objects = {make_object(7, ShapeKind::sphere, {0.5, 0.5, 0.5}, centre)};
  const Pose& pose = scene.trajectory[0];
  const FrameBuffers frame = Renderer(scene).render(pose, 0);
  const int count =
      for_each_back_projected(scene, frame, pose, [&](const Eigen::Vector3d& p, int x, int y) {
        ASSERT_NEAR((p - centre).norm(), 0.5, 1e-4);
        const Eigen::Vector3d normal(frame.normal.at(x, y, 0), frame.normal.at(x, y, 1),
                                     frame.normal.at(x, y, 2));
        ASSERT_NEAR(normal.dot((p - centre).normalized()), 1.0, 1e-4);
        ASSERT_EQ(frame.segment.at(x, y, 0), 7);
      });
  EXPECT_GT(count, 300);
}

TEST(Renderer, BoxBetweenLightAndPlaneCastsAnExactlyBlackShadow) {
  Scene scene = plane_scene();
  scene.lights[0].position = {0, 2, 0};
  // A box 0.4 m wide floating at 1 m: its shadow on the plane is a square of 0.8 m side.
  scene.objects.push_back(make_object(2, ShapeKind::box, {0.4, 0.1, 0.4}, {0, 1, 0}));
  const Pose& pose = scene.trajectory[0];
  const FrameBuffers shadowed = Renderer(scene).render(pose, 0);
  scene.shadows = false;
  const FrameBuffers unshadowed = Renderer(scene).render(pose, 0);
  int umbra = 0, lit = 0;
  for_each_back_projected(scene, shadowed, pose, [&](const Eigen::Vector3d& p, int x, int y) {
    if (shadowed.segment.at(x, y, 0) != 1) return;
    // At height h the segment from p to the light (0, 2, 0) is at (1 - h / 2) p in x and z;
    // where it meets the box's bottom face (h = 0.95) inside the box, p is in the umbra.
    const Eigen::Vector2d crossing = (1 - 0.95 / 2) * Eigen::Vector2d(p.x(), p.z());
    const double margin = 0.02;
    if (crossing.cwiseAbs().maxCoeff() < 0.2 - margin) {
      for (int c = 0; c < 3; ++c) ASSERT_EQ(shadowed.radiance.at(x, y, c), 0.0f);
      ASSERT_GT(unshadowed.radiance.at(x, y, 0), 0.0f);
      ++umbra;
    } else if (crossing.cwiseAbs().maxCoeff() > 0.25 + margin) {
      ASSERT_GT(shadowed.radiance.at(x, y, 0), 0.0f);
      ++lit;
    }
  });
  EXPECT_GT(umbra, 100);
  EXPECT_GT(lit, 1000);
}

TEST(Renderer, LightProxyIsEmissiveAndCastsNoShadow) {
  Scene scene = plane_scene();
  scene.lights[0].position = {0, 0.3, 0};
  scene.lights[0].proxy_radius_m = 0.05;
  const Pose& pose = scene.trajectory[0];
  const FrameBuffers frame = Renderer(scene).render(pose, 0);
  const Eigen::Vector2d pixel =
      scene.camera.intrinsics.project(pose.inverse() * scene.lights[0].position);
  const int x = int(std::lround(pixel.x())), y = int(std::lround(pixel.y()));
  const float emitted = scene.lights[0].intensity.x() / float(M_PI * 0.05 * 0.05);
  EXPECT_FLOAT_EQ(frame.radiance.at(x, y, 0), emitted);
  EXPECT_EQ(frame.segment.at(x, y, 0), 0);
  EXPECT_GT(frame.depth.at(x, y, 0), 0.0f);
  // Directly below the light the plane is lit although the proxy sits between them.
  const Eigen::Vector2d below =
      scene.camera.intrinsics.project(pose.inverse() * Eigen::Vector3d(0.12, 0, 0));
  EXPECT_GT(frame.radiance.at(int(below.x()), int(below.y()), 0), 0.0f);
}

TEST(Renderer, ConstantEnvironmentLightsADiffusePlaneWithItsAlbedo) {
  test::TemporaryFolder folder;
  const std::string map = folder.path("white.exr");
  io::write_image(map, ImageF(32, 16, 3, 1.0f));
  Scene scene = plane_scene();
  scene.lights.clear();
  scene.shadows = false;
  scene.objects[0].material.ward = WardMaterial{{0.5f, 0.5f, 0.5f}, {0, 0, 0}, 0.1f};
  scene.environment = Environment{map, 1.0f, 0.0f, 256};
  const Pose& pose = scene.trajectory[0];
  const Renderer renderer(scene);
  const FrameBuffers frame = renderer.render(pose, 0);
  double sum = 0;
  int surface = 0;
  for (std::size_t i = 0; i < frame.depth.pixel_count(); ++i) {
    if (frame.depth.plane(0)[i] > 0) {
      sum += frame.radiance.plane(0)[i];
      ++surface;
    } else {
      EXPECT_NEAR(frame.radiance.plane(0)[i], 1.0f, 1e-6f);  // the background shows the map
    }
  }
  // A uniform sky of radiance 1 gives irradiance pi, so L = kd (Monte Carlo: 2%).
  EXPECT_NEAR(sum / surface, 0.5, 0.01);
  // Seeded: the same frame again is identical, another frame index is not.
  EXPECT_EQ(renderer.render(pose, 0).radiance.values(), frame.radiance.values());
  EXPECT_NE(renderer.render(pose, 1).radiance.values(), frame.radiance.values());
}

}  // namespace
}  // namespace glint::render
