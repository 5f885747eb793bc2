#pragma once
// The Embree side of the renderer: one device and two committed scenes built once from a
// render::Scene, plus a record per Embree geometry with what shading needs.
//  - camera_scene(): every object and the light proxy spheres (what camera rays see);
//  - shadow_scene(): the objects only, so proxies never cast shadows.
// Geometry IDs are shared by both scenes and index surfaces(). World-space vertices; meshes
// are loaded, normalised (scene.h) and transformed here. Read-only after construction.
#include <embree3/rtcore.h>

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <memory>
#include <vector>

#include "render/scene.h"
#include "render/texture.h"

namespace glint::render {

enum class SurfaceKind { triangles, sphere, light_proxy };

struct Surface {
  SurfaceKind kind = SurfaceKind::triangles;
  std::uint16_t segment_id = 0;  // Object::id, 0 for light proxies
  WardMaterial material;
  std::shared_ptr<const Texture> kd_texture;  // null: material.kd everywhere
  float texture_scale_m = 1;
  Eigen::Isometry3f world_to_object = Eigen::Isometry3f::Identity();
  // triangles: world-space geometry; vertex_normals empty = flat shading (boxes, planes)
  std::vector<Eigen::Vector3i> triangles;
  std::vector<Eigen::Vector3f> vertex_normals;
  std::vector<Eigen::Vector2f> corner_uvs;  // 3 per triangle, or empty
  // sphere and light_proxy
  Eigen::Vector3f center = Eigen::Vector3f::Zero();
  float radius = 0;
  Eigen::Vector3f emitted_radiance = Eigen::Vector3f::Zero();  // light_proxy only
};

// A ray for Embree's queries: from origin along unit direction up to far, every geometry.
inline RTCRay embree_ray(const Eigen::Vector3f& origin, const Eigen::Vector3f& direction,
                         float far) {
  RTCRay ray;
  ray.org_x = origin.x();
  ray.org_y = origin.y();
  ray.org_z = origin.z();
  ray.dir_x = direction.x();
  ray.dir_y = direction.y();
  ray.dir_z = direction.z();
  ray.tnear = 0.0f;
  ray.tfar = far;
  ray.mask = ~0u;
  ray.id = 0;
  ray.flags = 0;
  ray.time = 0.0f;
  return ray;
}

class EmbreeScene {
 public:
  // Throws glint::Error naming the mesh or texture file that cannot be read, or the object
  // ("objects[i] 'name'") with a non-positive size.
  explicit EmbreeScene(const Scene& scene);
  ~EmbreeScene();
  EmbreeScene(const EmbreeScene&) = delete;
  EmbreeScene& operator=(const EmbreeScene&) = delete;

  RTCScene camera_scene() const { return camera_scene_; }
  RTCScene shadow_scene() const { return shadow_scene_; }
  const Surface& surface(unsigned geometry_id) const { return surfaces_[geometry_id]; }
  // Whether an object (not a light proxy) lies on the ray within `distance`; thread-safe.
  bool occluded(const Eigen::Vector3f& origin, const Eigen::Vector3f& direction,
                float distance) const;

 private:
  void add_triangles(Surface surface, const std::vector<Eigen::Vector3f>& world_vertices);
  void add_sphere(Surface surface, bool casts_shadows);

  RTCDevice device_ = nullptr;
  RTCScene camera_scene_ = nullptr;
  RTCScene shadow_scene_ = nullptr;
  std::vector<Surface> surfaces_;
};

}  // namespace glint::render
