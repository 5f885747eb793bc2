#pragma once
// Ray caster and path tracer for render::Scene on Embree 3. Direct light: one camera ray
// through each pixel centre, shaded with the Ward BRDF (paper 1 eqs 2-4) under the scene's
// near-field point lights
//   L_o = sum_lights  I / r^2 * f(wi, wo) * cos(theta_i)     (times visibility with shadows)
// plus, optionally, the environment map (importance-sampled, scene.environment->samples rays
// per pixel, seeded by scene.seed and the frame index). With scene.bounces = 0 (the default)
// that is all: no interreflections, no ambient term, a surface no light sees is exactly black,
// as the reflectance pipeline assumes. With scene.bounces = N > 0 the indirect light of paths
// up to N vertices beyond the visible one is added, path traced with scene.indirect_samples
// paths per pixel: Ward importance sampling (render/ward_sampling.h), next-event estimation to
// every point light (and one environment sample) at every vertex; the direct part stays exact,
// so N = 0 gives the direct image bit for bit and N > 0 only adds the indirect estimate.
// Every random number comes from a counter-based stream keyed by (seed, frame, pixel), so an
// image does not depend on the thread count or scheduling.
// Surfaces are two-sided (normals face the camera). Light proxies are emissive spheres of
// radiance I / (pi r^2), seen by camera rays but transparent to shadow and bounce rays (their
// light arrives through the point light it stands for); their pixels get depth and normal but
// segment 0 and zero material maps. Background: the environment's radiance, or 0.
// Thread safety: render() is const and may run concurrently.
#include <cstdint>
#include <memory>

#include "core/camera.h"
#include "core/image.h"
#include "render/scene.h"

namespace glint::render {

// One frame's noise-free buffers at the scene's intrinsics resolution, row-major planes.
struct FrameBuffers {
  ImageF radiance;               // 3 ch, linear RGB scene radiance (before exposure)
  ImageF depth;                  // 1 ch, z-depth along the optical axis in metres, 0 = none
  ImageF normal;                 // 3 ch, unit world-space shading normal, 0 = none
  Image<std::uint16_t> segment;  // 1 ch, Object::id, 0 = background or light proxy
  ImageF kd, ks;                 // 3 ch, linear Ward albedos (kd from the texture if any)
  ImageF alpha;                  // 1 ch, Ward roughness, 0 = none
};

class Renderer {
 public:
  // Loads meshes, textures and the environment map and builds the Embree scene once. Throws
  // glint::Error naming the file for unreadable inputs, or the object for invalid shapes.
  explicit Renderer(const Scene& scene);
  ~Renderer();
  Renderer(Renderer&&) noexcept;
  Renderer& operator=(Renderer&&) noexcept;
  Renderer(const Renderer&) = delete;
  Renderer& operator=(const Renderer&) = delete;

  // Renders the view from camera_to_world; frame_index seeds the environment and path sampling.
  FrameBuffers render(const Pose& camera_to_world, int frame_index) const;

  const Scene& scene() const;

  // The irradiance at surface point p (unit normal n, facing where the light comes from) of all
  // light but the point lights' direct light: the light bounced off the scene (paths of up to
  // scene.bounces vertices, as render() adds them) and the environment's. Monte Carlo over
  // `paths` paths, seeded by scene.seed and `key`. The oracle of `glint reconstruct
  // --gt-indirect`; zero without bounces or an environment.
  Eigen::Vector3f indirect_irradiance(const Eigen::Vector3f& p, const Eigen::Vector3f& n, int paths,
                                      std::uint64_t key) const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace glint::render
