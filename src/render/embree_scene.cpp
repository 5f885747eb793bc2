#include "render/embree_scene.h"

#include <fmt/format.h>

#include <array>
#include <map>

#include "core/error.h"
#include "render/mesh_loader.h"

namespace glint::render {
namespace {

void throw_on_device_error(RTCDevice device, const std::string& what) {
  const RTCError error = rtcGetDeviceError(device);
  if (error != RTC_ERROR_NONE)
    throw Error("embree", what, fmt::format("Embree error code {}", static_cast<int>(error)));
}

std::string object_label(const Scene& scene, std::size_t index) {
  return fmt::format("objects[{}] '{}'", index, scene.objects[index].name);
}

// Box centred on the origin: 8 corners, 12 outward-facing counter-clockwise triangles.
TriangleMesh box_mesh(const Eigen::Vector3f& size) {
  TriangleMesh mesh;
  for (int corner = 0; corner < 8; ++corner)
    mesh.vertices.emplace_back((corner & 1 ? 0.5f : -0.5f) * size.x(),
                               (corner & 2 ? 0.5f : -0.5f) * size.y(),
                               (corner & 4 ? 0.5f : -0.5f) * size.z());
  mesh.triangles = {{0, 4, 6}, {0, 6, 2}, {1, 3, 7}, {1, 7, 5},   // -x, +x
                    {0, 1, 5}, {0, 5, 4}, {2, 6, 7}, {2, 7, 3},   // -y, +y
                    {0, 2, 3}, {0, 3, 1}, {4, 5, 7}, {4, 7, 6}};  // -z, +z
  return mesh;
}

// Plane y = 0 centred on the origin, normal +y.
TriangleMesh plane_mesh(const Eigen::Vector3f& size) {
  const float x = 0.5f * size.x(), z = 0.5f * size.z();
  TriangleMesh mesh;
  mesh.vertices = {{-x, 0, -z}, {x, 0, -z}, {x, 0, z}, {-x, 0, z}};
  mesh.triangles = {{0, 3, 2}, {0, 2, 1}};
  return mesh;
}

// Each file is read once per scene (several objects often share a mesh or a texture).
class MeshCache {
 public:
  const TriangleMesh& get(const std::string& path) {
    auto found = meshes_.find(path);
    if (found == meshes_.end()) found = meshes_.emplace(path, load_mesh(path)).first;
    return found->second;
  }

 private:
  std::map<std::string, TriangleMesh> meshes_;
};

class TextureCache {
 public:
  std::shared_ptr<const Texture> get(const std::string& path) {
    if (path.empty()) return nullptr;
    auto& slot = textures_[path];
    if (!slot) slot = std::make_shared<const Texture>(path);
    return slot;
  }

 private:
  std::map<std::string, std::shared_ptr<const Texture>> textures_;
};

}  // namespace

EmbreeScene::EmbreeScene(const Scene& scene) {
  device_ = rtcNewDevice(nullptr);
  if (!device_) throw Error("embree", "device", "cannot create an Embree device");
  camera_scene_ = rtcNewScene(device_);
  shadow_scene_ = rtcNewScene(device_);
  for (RTCScene s : {camera_scene_, shadow_scene_})
    rtcSetSceneBuildQuality(s, RTC_BUILD_QUALITY_HIGH);

  MeshCache meshes;
  TextureCache textures;
  for (std::size_t i = 0; i < scene.objects.size(); ++i) {
    const Object& object = scene.objects[i];
    if (!(object.size.minCoeff() > 0))
      throw Error("scene", object_label(scene, i), "sizes must be positive");
    Surface surface;
    surface.segment_id = static_cast<std::uint16_t>(object.id);
    surface.material = object.material.ward;
    surface.kd_texture = textures.get(object.material.kd_texture);
    surface.texture_scale_m = object.material.texture_scale_m;
    const Eigen::Isometry3f object_to_world = object.transform.cast<float>();
    surface.world_to_object = object_to_world.inverse();
    if (object.shape == ShapeKind::sphere) {
      surface.kind = SurfaceKind::sphere;
      surface.center = object_to_world.translation();
      surface.radius = static_cast<float>(object.size.x());
      add_sphere(std::move(surface), true);
      continue;
    }
    TriangleMesh mesh;
    const Eigen::Vector3f size = object.size.cast<float>();
    if (object.shape == ShapeKind::box) mesh = box_mesh(size);
    if (object.shape == ShapeKind::plane) mesh = plane_mesh(size);
    if (object.shape == ShapeKind::mesh) {
      mesh = meshes.get(object.mesh_path);
      Eigen::AlignedBox3f bounds;
      for (const Eigen::Vector3f& v : mesh.vertices) bounds.extend(v);
      if (!(bounds.sizes().y() > 0))
        throw Error(object.mesh_path, "", "the mesh has no height (y extent) to scale to size.y");
      normalise_mesh(mesh, object.size.y());
      surface.vertex_normals = vertex_normals(mesh);
      for (Eigen::Vector3f& n : surface.vertex_normals) n = object_to_world.linear() * n;
      surface.corner_uvs = std::move(mesh.corner_uvs);
    }
    std::vector<Eigen::Vector3f> world_vertices;
    world_vertices.reserve(mesh.vertices.size());
    for (const Eigen::Vector3f& v : mesh.vertices) world_vertices.push_back(object_to_world * v);
    surface.triangles = std::move(mesh.triangles);
    add_triangles(std::move(surface), world_vertices);
  }
  for (const PointLight& light : scene.lights) {
    if (!(light.proxy_radius_m > 0)) continue;
    Surface proxy;
    proxy.kind = SurfaceKind::light_proxy;
    proxy.center = light.position.cast<float>();
    proxy.radius = static_cast<float>(light.proxy_radius_m);
    // A sphere of radiance L has intensity pi r^2 L in every direction.
    proxy.emitted_radiance = light.intensity / (float(M_PI) * proxy.radius * proxy.radius);
    add_sphere(std::move(proxy), false);
  }
  rtcCommitScene(camera_scene_);
  rtcCommitScene(shadow_scene_);
  throw_on_device_error(device_, "scene build");
}

bool EmbreeScene::occluded(const Eigen::Vector3f& origin, const Eigen::Vector3f& direction,
                           float distance) const {
  RTCIntersectContext incoherent;
  rtcInitIntersectContext(&incoherent);
  RTCRay ray = embree_ray(origin, direction, distance);
  rtcOccluded1(shadow_scene_, &incoherent, &ray);
  return ray.tfar < 0.0f;  // Embree sets tfar to -inf on a hit
}

EmbreeScene::~EmbreeScene() {
  if (camera_scene_) rtcReleaseScene(camera_scene_);
  if (shadow_scene_) rtcReleaseScene(shadow_scene_);
  if (device_) rtcReleaseDevice(device_);
}

void EmbreeScene::add_triangles(Surface surface, const std::vector<Eigen::Vector3f>& vertices) {
  RTCGeometry geometry = rtcNewGeometry(device_, RTC_GEOMETRY_TYPE_TRIANGLE);
  auto* vertex_buffer = static_cast<float*>(rtcSetNewGeometryBuffer(
      geometry, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, 3 * sizeof(float), vertices.size()));
  auto* index_buffer = static_cast<unsigned*>(
      rtcSetNewGeometryBuffer(geometry, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3,
                              3 * sizeof(unsigned), surface.triangles.size()));
  throw_on_device_error(device_, "geometry buffers");
  for (std::size_t v = 0; v < vertices.size(); ++v)
    for (int c = 0; c < 3; ++c) vertex_buffer[3 * v + c] = vertices[v][c];
  for (std::size_t t = 0; t < surface.triangles.size(); ++t)
    for (int c = 0; c < 3; ++c) index_buffer[3 * t + c] = unsigned(surface.triangles[t][c]);
  rtcCommitGeometry(geometry);
  const auto id = static_cast<unsigned>(surfaces_.size());
  rtcAttachGeometryByID(camera_scene_, geometry, id);
  rtcAttachGeometryByID(shadow_scene_, geometry, id);
  rtcReleaseGeometry(geometry);
  surfaces_.push_back(std::move(surface));
}

void EmbreeScene::add_sphere(Surface surface, bool casts_shadows) {
  RTCGeometry geometry = rtcNewGeometry(device_, RTC_GEOMETRY_TYPE_SPHERE_POINT);
  auto* point = static_cast<float*>(rtcSetNewGeometryBuffer(
      geometry, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT4, 4 * sizeof(float), 1));
  throw_on_device_error(device_, "sphere buffer");
  point[0] = surface.center.x();
  point[1] = surface.center.y();
  point[2] = surface.center.z();
  point[3] = surface.radius;
  rtcCommitGeometry(geometry);
  const auto id = static_cast<unsigned>(surfaces_.size());
  rtcAttachGeometryByID(camera_scene_, geometry, id);
  if (casts_shadows) rtcAttachGeometryByID(shadow_scene_, geometry, id);
  rtcReleaseGeometry(geometry);
  surfaces_.push_back(std::move(surface));
}

}  // namespace glint::render
