#include "render/renderer.h"

#include <cmath>
#include <limits>
#include <optional>
#include <vector>

#include "core/parallel.h"
#include "render/embree_scene.h"
#include "render/environment_map.h"
#include "render/random.h"
#include "render/ward_sampling.h"

namespace glint::render {
namespace {

constexpr float kInfinity = std::numeric_limits<float>::infinity();
// Shadow rays start this far off the surface (along the geometric normal) and stop this far
// short of the light, relative to the distance travelled: no self-shadowing "acne".
constexpr float kShadowOffsetM = 1e-4f;

// What shading needs at a camera ray's hit.
struct Hit {
  Eigen::Vector3f position;
  Eigen::Vector3f geometric_normal;  // unit, facing the camera
  Eigen::Vector3f shading_normal;    // unit, on the geometric normal's side
  Eigen::Vector3f kd;
};

// Texture coordinates by planar projection along the dominant axis of the object-space normal.
Eigen::Vector2f box_projection(const Surface& surface, const Eigen::Vector3f& world_position,
                               const Eigen::Vector3f& world_normal) {
  const Eigen::Vector3f p = surface.world_to_object * world_position / surface.texture_scale_m;
  const Eigen::Vector3f n = (surface.world_to_object.linear() * world_normal).cwiseAbs();
  if (n.y() >= n.x() && n.y() >= n.z()) return {p.x(), -p.z()};
  if (n.x() >= n.z()) return {-p.z(), p.y()};
  return {p.x(), p.y()};
}

Hit surface_hit(const Surface& surface, const RTCRayHit& ray_hit, const Eigen::Vector3f& origin,
                const Eigen::Vector3f& direction) {
  Hit hit;
  hit.position = origin + ray_hit.ray.tfar * direction;
  Eigen::Vector2f uv = Eigen::Vector2f::Zero();
  bool has_uv = false;
  if (surface.kind == SurfaceKind::triangles) {
    hit.geometric_normal =
        Eigen::Vector3f(ray_hit.hit.Ng_x, ray_hit.hit.Ng_y, ray_hit.hit.Ng_z).normalized();
    hit.shading_normal = hit.geometric_normal;
    const float b1 = ray_hit.hit.u, b2 = ray_hit.hit.v, b0 = 1.0f - b1 - b2;
    const Eigen::Vector3i& t = surface.triangles[ray_hit.hit.primID];
    if (!surface.vertex_normals.empty()) {
      const Eigen::Vector3f n = b0 * surface.vertex_normals[t[0]] +
                                b1 * surface.vertex_normals[t[1]] +
                                b2 * surface.vertex_normals[t[2]];
      if (n.squaredNorm() > 0) hit.shading_normal = n.normalized();
    }
    if (!surface.corner_uvs.empty()) {
      const std::size_t corner = 3 * std::size_t(ray_hit.hit.primID);
      uv = b0 * surface.corner_uvs[corner] + b1 * surface.corner_uvs[corner + 1] +
           b2 * surface.corner_uvs[corner + 2];
      has_uv = true;
    }
  } else {  // exact sphere normal
    hit.geometric_normal = (hit.position - surface.center).normalized();
    hit.shading_normal = hit.geometric_normal;
  }
  // Two-sided surfaces: the geometric normal faces the camera, the shading normal follows it.
  if (hit.geometric_normal.dot(direction) > 0) hit.geometric_normal = -hit.geometric_normal;
  if (hit.shading_normal.dot(hit.geometric_normal) < 0) hit.shading_normal = -hit.shading_normal;
  hit.kd = surface.material.kd;
  if (surface.kd_texture) {
    if (!has_uv) uv = box_projection(surface, hit.position, hit.geometric_normal);
    hit.kd = surface.kd_texture->lookup(uv.x(), uv.y());
  }
  return hit;
}

RTCIntersectContext context(bool coherent) {
  RTCIntersectContext context;
  rtcInitIntersectContext(&context);
  if (coherent) context.flags = RTC_INTERSECT_CONTEXT_FLAG_COHERENT;
  return context;
}

// Point-light geometry at a hit: unit direction, distance, and whether the light is in front.
struct LightPath {
  Eigen::Vector3f wi;
  float distance;
  float distance2;
  bool faces_light;
};
LightPath light_path(const Hit& hit, const PointLight& light) {
  const Eigen::Vector3f to_light = light.position.cast<float>() - hit.position;
  LightPath path;
  path.distance2 = to_light.squaredNorm();
  path.distance = std::sqrt(path.distance2);
  path.wi = to_light / path.distance;
  path.faces_light =
      hit.shading_normal.dot(path.wi) > 0.0f && hit.geometric_normal.dot(path.wi) > 0.0f;
  return path;
}

Eigen::Vector3f shadow_origin(const Hit& hit) {
  return hit.position + kShadowOffsetM * hit.geometric_normal;
}

// Per-thread scratch for one image row: the camera rays, the hits, and per light the shadow
// rays (packed) and which pixels see it. Allocated once per chunk of rows.
struct RowScratch {
  explicit RowScratch(int width, std::size_t lights)
      : camera_rays(width),
        hits(width),
        shaded(width),
        shadow_rays(width),
        shadow_pixels(width),
        light_visible(lights * width) {}
  std::vector<RTCRayHit> camera_rays;
  std::vector<Hit> hits;
  std::vector<std::uint8_t> shaded;  // 1 where hits[x] is a surface to shade
  std::vector<RTCRay> shadow_rays;
  std::vector<int> shadow_pixels;
  std::vector<std::uint8_t> light_visible;  // [light * width + x]
};

}  // namespace

struct Renderer::Impl {
  explicit Impl(const Scene& s) : scene(s), embree(s) {
    if (s.environment) environment.emplace(*s.environment);
  }

  // Direct lighting at a hit seen along -wo (paper 1, eq. 1 with eqs 2-4): the point lights
  // (visibility of light l at light_visible[l * stride + x], from the row's shadow rays) and the
  // importance-sampled environment.
  Eigen::Vector3f shade(const Hit& hit, const WardMaterial& material, const Eigen::Vector3f& wo,
                        const std::vector<std::uint8_t>& light_visible, std::size_t x,
                        std::size_t stride, std::uint64_t pixel, int frame_index) const {
    Eigen::Vector3f radiance = Eigen::Vector3f::Zero();
    for (std::size_t l = 0; l < scene.lights.size(); ++l)
      if (light_visible[l * stride + x])
        radiance += point_light(hit, material, wo, light_path(hit, scene.lights[l]), l);
    if (!environment) return radiance;
    return radiance + environment_mean(hit, material, wo, std::max(1, scene.environment->samples),
                                       pixel, frame_index);
  }

  // The environment's direct light at a hit: the mean of `samples` importance samples.
  Eigen::Vector3f environment_mean(const Hit& hit, const WardMaterial& material,
                                   const Eigen::Vector3f& wo, int samples, std::uint64_t pixel,
                                   int frame_index) const {
    PixelRandom random(scene.seed, frame_index, pixel, RandomPurpose::environment);
    Eigen::Vector3f sum = Eigen::Vector3f::Zero();
    for (int s = 0; s < samples; ++s) sum += environment_sample(hit, material, wo, random);
    return sum / float(samples);
  }

  // Light l's term of eq. (1): I / r^2 f(wi, wo) cos(theta_i), visibility already decided.
  Eigen::Vector3f point_light(const Hit& hit, const WardMaterial& material,
                              const Eigen::Vector3f& wo, const LightPath& path,
                              std::size_t l) const {
    const Eigen::Vector3f& n = hit.shading_normal;
    return (scene.lights[l].intensity / path.distance2)
               .cwiseProduct(ward_brdf(material, n, path.wi, wo)) *
           n.dot(path.wi);
  }

  // One importance sample of the environment's term (its estimate's mean is the term).
  Eigen::Vector3f environment_sample(const Hit& hit, const WardMaterial& material,
                                     const Eigen::Vector3f& wo, PixelRandom& random) const {
    const Eigen::Vector3f& n = hit.shading_normal;
    const EnvironmentSample sample = environment->sample(random.uniform(), random.uniform());
    const float cos_i = n.dot(sample.direction);
    if (cos_i <= 0.0f || hit.geometric_normal.dot(sample.direction) <= 0.0f)
      return Eigen::Vector3f::Zero();
    if (scene.shadows && embree.occluded(shadow_origin(hit), sample.direction, kInfinity))
      return Eigen::Vector3f::Zero();
    return sample.radiance.cwiseProduct(ward_brdf(material, n, sample.direction, wo)) *
           (cos_i / sample.pdf);
  }

  // Direct light at a path vertex: every point light with its own shadow ray (when the scene
  // has shadows) and one environment sample.
  Eigen::Vector3f vertex_direct(const Hit& hit, const WardMaterial& material,
                                const Eigen::Vector3f& wo, PixelRandom& random) const {
    Eigen::Vector3f radiance = Eigen::Vector3f::Zero();
    for (std::size_t l = 0; l < scene.lights.size(); ++l) {
      const LightPath path = light_path(hit, scene.lights[l]);
      if (!path.faces_light) continue;
      if (scene.shadows &&
          embree.occluded(shadow_origin(hit), path.wi, path.distance * (1.0f - kShadowOffsetM)))
        continue;
      radiance += point_light(hit, material, wo, path, l);
    }
    if (environment) radiance += environment_sample(hit, material, wo, random);
    return radiance;
  }

  // Indirect light at the camera's hit (the rendering equation's remaining terms up to
  // scene.bounces further vertices): the mean of `paths` paths (render() takes
  // scene.indirect_samples per pixel), each direction drawn from the Ward mixture
  // (render/ward_sampling.h), next-event estimation at every vertex after the first. Emission
  // reaches the path only through next-event estimation: bounce rays trace the shadow scene, so
  // they pass through light proxies (the point lights they stand for are sampled directly), and
  // a ray that leaves the scene adds nothing (the environment is sampled directly too); no light
  // is counted twice. A fixed length, no Russian roulette.
  Eigen::Vector3f indirect(const Hit& first_hit, const WardMaterial& first_material,
                           const Eigen::Vector3f& first_wo, int paths, std::uint64_t pixel,
                           int frame_index) const {
    PixelRandom random(scene.seed, frame_index, pixel, RandomPurpose::indirect);
    RTCIntersectContext incoherent = context(false);
    Eigen::Vector3f sum = Eigen::Vector3f::Zero();
    for (int s = 0; s < paths; ++s) {
      Hit hit = first_hit;
      WardMaterial material = first_material;
      Eigen::Vector3f wo = first_wo;
      Eigen::Vector3f throughput = Eigen::Vector3f::Ones();
      for (int bounce = 0; bounce < scene.bounces; ++bounce) {
        const float u_lobe = random.uniform(), u1 = random.uniform(), u2 = random.uniform();
        const BrdfSample sample =
            sample_ward_brdf(material, hit.shading_normal, wo, u_lobe, u1, u2);
        if (sample.pdf <= 0.0f || hit.geometric_normal.dot(sample.direction) <= 0.0f) break;
        throughput = throughput.cwiseProduct(sample.weight);
        const Eigen::Vector3f origin = shadow_origin(hit);
        RTCRayHit ray_hit;
        ray_hit.ray = embree_ray(origin, sample.direction, kInfinity);
        ray_hit.hit.geomID = RTC_INVALID_GEOMETRY_ID;
        ray_hit.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
        rtcIntersect1(embree.shadow_scene(), &incoherent, &ray_hit);
        if (ray_hit.hit.geomID == RTC_INVALID_GEOMETRY_ID) break;
        const Surface& surface = embree.surface(ray_hit.hit.geomID);
        hit = surface_hit(surface, ray_hit, origin, sample.direction);
        material = surface.material;
        material.kd = hit.kd;
        wo = -sample.direction;
        sum += throughput.cwiseProduct(vertex_direct(hit, material, wo, random));
      }
    }
    return sum / float(paths);
  }

  // Which pixels of the row see each light: one coherent stream of shadow rays per light.
  void trace_shadows(RowScratch& row, int width) const {
    RTCIntersectContext coherent = context(true);
    for (std::size_t l = 0; l < scene.lights.size(); ++l) {
      std::uint8_t* visible = row.light_visible.data() + l * width;
      unsigned count = 0;
      for (int x = 0; x < width; ++x) {
        visible[x] = 0;
        if (!row.shaded[x]) continue;
        const LightPath path = light_path(row.hits[x], scene.lights[l]);
        if (!path.faces_light) continue;
        visible[x] = 1;
        if (!scene.shadows) continue;
        row.shadow_rays[count] = embree_ray(shadow_origin(row.hits[x]), path.wi,
                                            path.distance * (1.0f - kShadowOffsetM));
        row.shadow_pixels[count++] = x;
      }
      if (count == 0) continue;
      rtcOccluded1M(embree.shadow_scene(), &coherent, row.shadow_rays.data(), count,
                    sizeof(RTCRay));
      for (unsigned i = 0; i < count; ++i)
        if (row.shadow_rays[i].tfar < 0.0f) visible[row.shadow_pixels[i]] = 0;
    }
  }

  Scene scene;
  EmbreeScene embree;
  std::optional<EnvironmentMap> environment;
};

Renderer::Renderer(const Scene& scene) : impl_(std::make_unique<Impl>(scene)) {}
Renderer::~Renderer() = default;
Renderer::Renderer(Renderer&&) noexcept = default;
Renderer& Renderer::operator=(Renderer&&) noexcept = default;

const Scene& Renderer::scene() const { return impl_->scene; }

Eigen::Vector3f Renderer::indirect_irradiance(const Eigen::Vector3f& p, const Eigen::Vector3f& n,
                                              int paths, std::uint64_t key) const {
  // A white diffuse surface reflects E / pi of any irradiance E: its indirect radiance (and its
  // direct radiance from the environment), times pi.
  const Hit hit{p, n, n, Eigen::Vector3f::Ones()};
  const WardMaterial white{{1, 1, 1}, {0, 0, 0}, 0.1f};
  Eigen::Vector3f radiance = Eigen::Vector3f::Zero();
  if (impl_->scene.bounces > 0) radiance = impl_->indirect(hit, white, n, paths, key, 0);
  if (impl_->environment) radiance += impl_->environment_mean(hit, white, n, paths, key, 0);
  return float(M_PI) * radiance;
}

FrameBuffers Renderer::render(const Pose& camera_to_world, int frame_index) const {
  const Impl& impl = *impl_;
  const Intrinsics& intrinsics = impl.scene.camera.intrinsics;
  const int width = intrinsics.width, height = intrinsics.height;
  FrameBuffers out{ImageF(width, height, 3), ImageF(width, height, 1),
                   ImageF(width, height, 3), Image<std::uint16_t>(width, height, 1),
                   ImageF(width, height, 3), ImageF(width, height, 3),
                   ImageF(width, height, 1)};
  const Eigen::Matrix3f rotation = camera_to_world.linear().cast<float>();
  const Eigen::Vector3f origin = camera_to_world.translation().cast<float>();

  parallel_for_chunks(std::size_t(height), 2, [&](std::size_t row_begin, std::size_t row_end) {
    RowScratch row(width, impl.scene.lights.size());
    for (std::size_t y = row_begin; y < row_end; ++y) {
      // Camera rays with camera-space z = 1, so the hit distance t is the z-depth.
      for (int x = 0; x < width; ++x) {
        const Eigen::Vector3f direction = rotation * intrinsics.ray(x, double(y)).cast<float>();
        RTCRayHit& ray_hit = row.camera_rays[x];
        ray_hit.ray = embree_ray(origin, direction, kInfinity);
        ray_hit.hit.geomID = RTC_INVALID_GEOMETRY_ID;
        ray_hit.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
      }
      RTCIntersectContext coherent = context(true);
      rtcIntersect1M(impl.embree.camera_scene(), &coherent, row.camera_rays.data(), width,
                     sizeof(RTCRayHit));
      for (int x = 0; x < width; ++x) {
        const RTCRayHit& ray_hit = row.camera_rays[x];
        const unsigned geometry = ray_hit.hit.geomID;
        row.shaded[x] = geometry != RTC_INVALID_GEOMETRY_ID &&
                        impl.embree.surface(geometry).kind != SurfaceKind::light_proxy;
        if (geometry == RTC_INVALID_GEOMETRY_ID) continue;
        const Eigen::Vector3f direction(ray_hit.ray.dir_x, ray_hit.ray.dir_y, ray_hit.ray.dir_z);
        row.hits[x] = surface_hit(impl.embree.surface(geometry), ray_hit, origin, direction);
      }
      impl.trace_shadows(row, width);

      for (int x = 0; x < width; ++x) {
        const std::size_t pixel = y * width + x;
        const RTCRayHit& ray_hit = row.camera_rays[x];
        const Eigen::Vector3f unit_direction =
            Eigen::Vector3f(ray_hit.ray.dir_x, ray_hit.ray.dir_y, ray_hit.ray.dir_z).normalized();
        Eigen::Vector3f radiance = Eigen::Vector3f::Zero();
        if (ray_hit.hit.geomID == RTC_INVALID_GEOMETRY_ID) {
          if (impl.environment) radiance = impl.environment->radiance(unit_direction);
        } else {
          const Surface& surface = impl.embree.surface(ray_hit.hit.geomID);
          const Hit& hit = row.hits[x];
          out.depth.plane(0)[pixel] = ray_hit.ray.tfar;
          for (int c = 0; c < 3; ++c) out.normal.plane(c)[pixel] = hit.shading_normal[c];
          radiance = surface.emitted_radiance;
          if (row.shaded[x]) {
            WardMaterial material = surface.material;
            material.kd = hit.kd;
            radiance = impl.shade(hit, material, -unit_direction, row.light_visible, x, width,
                                  pixel, frame_index);
            if (impl.scene.bounces > 0)
              radiance += impl.indirect(hit, material, -unit_direction, impl.scene.indirect_samples,
                                        pixel, frame_index);
            out.segment.plane(0)[pixel] = surface.segment_id;
            for (int c = 0; c < 3; ++c) {
              out.kd.plane(c)[pixel] = material.kd[c];
              out.ks.plane(c)[pixel] = material.ks[c];
            }
            out.alpha.plane(0)[pixel] = material.alpha;
          }
        }
        for (int c = 0; c < 3; ++c) out.radiance.plane(c)[pixel] = radiance[c];
      }
    }
  });
  return out;
}

}  // namespace glint::render
