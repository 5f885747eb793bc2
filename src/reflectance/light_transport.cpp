#include "reflectance/light_transport.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>

#include "core/error.h"
#include "core/parallel.h"
#include "core/robust_statistics.h"
#include "fusion/ray_queue.h"
#include "fusion/tsdf_sampler.h"
#include "reflectance/hemi_image.h"
#include "reflectance/hit_radiance.h"
#include "render/embree_scene.h"
#include "render/renderer.h"
#include "render/ward_sampling.h"

namespace glint::reflectance {
namespace {

// SplitMix64's finaliser: a voxel's grid coordinates and the seed to its sequence's offset.
std::uint64_t mix(std::uint64_t z) {
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
  return z ^ (z >> 31);
}

float fraction(float x) { return x - std::floor(x); }

// Past an empty region's face: enough that rounding cannot hold the walk on it.
constexpr float kGrazingStepM = 1e-4f;

// Voxels whose rays are queued and marched together (fusion::RayQueue): enough rays to keep its
// lanes busy, few enough that the queue stays in L1.
constexpr std::size_t kVoxelsPerQueue = 16;

// The box of the allocated blocks in metres, and where a ray from inside it leaves it.
struct WorldBox {
  bool known = false;
  Eigen::Vector3f low, high;
  WorldBox(const fusion::BlockOccupancy& occupancy, const fusion::TsdfVolume& volume) {
    Eigen::Vector3i low_block, high_block;
    if (!occupancy.bounds(low_block, high_block)) return;
    const float block = float(volume.params().block_size_m());
    low = low_block.cast<float>() * block;
    high = (high_block + Eigen::Vector3i::Ones()).cast<float>() * block;
    known = true;
  }
  float exit(const Eigen::Vector3f& origin, const Eigen::Vector3f& direction) const {
    return known ? std::max(fusion::box_exit(origin, direction, low, high), 0.0f) : INFINITY;
  }
};

// Whether h lies on the proxy sphere of one of the lights: its direct light is already counted.
bool on_light(const std::vector<render::PointLight>& lights, const Eigen::Vector3f& h,
              float margin) {
  for (const render::PointLight& light : lights)
    if ((light.position.cast<float>() - h).norm() <= float(light.proxy_radius_m) + margin)
      return true;
  return false;
}

// The end of a shadow ray short of the light (its proxy and a margin of two TSDF voxels).
float shadow_ray_end(const render::PointLight& light, float distance,
                     const fusion::TsdfVolume& volume) {
  return distance - float(light.proxy_radius_m) - 2 * float(volume.params().voxel_size_m);
}

// Point p's shadow rays (unit normal n), one per light in front of it (of the first
// kMaxShadowedLights), from p + offset_m * n to short of the light's proxy:
// cast(origin, unit direction, t_max, light index).
template <class Cast>
void for_each_shadow_ray(const fusion::TsdfVolume& volume,
                         const std::vector<render::PointLight>& lights, const Eigen::Vector3f& p,
                         const Eigen::Vector3f& n, float offset_m, Cast&& cast) {
  const Eigen::Vector3f origin = p + offset_m * n;
  const std::size_t shadowed = std::min(lights.size(), std::size_t(kMaxShadowedLights));
  for (std::size_t l = 0; l < shadowed; ++l) {
    const Eigen::Vector3f to_light = lights[l].position.cast<float>() - origin;
    if (!(n.dot(to_light) > 0)) continue;  // behind the surface: it gets no light anyway
    const float distance = to_light.norm();
    const float t_max = shadow_ray_end(lights[l], distance, volume);
    if (!(t_max > 0)) continue;
    cast(origin, Eigen::Vector3f(to_light / distance), t_max, l);
  }
}

// A hash of three integers: a voxel's grid coordinates (its random numbers then do not depend on
// where in the pools it lies, which follows the threads' order of allocation) or a point's bits.
std::uint64_t place_hash(const Eigen::Vector3i& place) {
  return mix(std::uint64_t(std::uint32_t(place.x())) ^
             std::uint64_t(std::uint32_t(place.y())) << 21 ^
             std::uint64_t(std::uint32_t(place.z())) << 42);
}

// The additive recurrence of the plastic number (Roberts' R2): low-discrepancy in [0, 1)^2 for
// any number of points, so a point's first n directions stratify whatever n is; shifted
// (Cranley-Patterson) by a hash, so that each voxel or pixel has its own.
class ShiftedR2 {
 public:
  explicit ShiftedR2(std::uint64_t hash)
      : shift_a_(float(hash >> 40) * 0x1p-24f),
        shift_b_(float((hash >> 16) & 0xFFFFFF) * 0x1p-24f) {}
  // Point `index` of the sequence (an integer below 2^22, exact in a float).
  Eigen::Vector2f operator()(float index) const {
    constexpr float kR2a = 0.75487766624669276f, kR2b = 0.56984029099805327f;
    return {fraction(shift_a_ + index * kR2a), fraction(shift_b_ + index * kR2b)};
  }

 private:
  float shift_a_, shift_b_;
};

// Queues voxel v's next `rays` gather rays: cosine-weighted directions from its ShiftedR2
// sequence (hashed by its place), whose index `next` advances.
void queue_gather_rays(const ObservationGrid& grid, int v, int rays,
                       const LightTransportParams& params, const WorldBox& box, std::uint32_t& next,
                       fusion::RayQueue& queue) {
  const Eigen::Vector3f& normal = grid.normal(v);
  const Eigen::Matrix3f to_world = local_frame(normal).transpose();
  const Eigen::Vector3f origin = grid.position(v) + params.ray_offset_m * normal;
  const ShiftedR2 sequence(mix(params.seed ^ place_hash(grid.voxel_coordinates(v))));
  for (int k = 0; k < rays; ++k) {
    const Eigen::Vector2f u = sequence(float(next++ % (1u << 22)));
    const float u1 = u.x(), u2 = u.y();
    const float radius = std::sqrt(u1), phi = 2 * float(M_PI) * u2;
    const Eigen::Vector3f direction =
        to_world * Eigen::Vector3f(radius * std::cos(phi), radius * std::sin(phi),
                                   std::sqrt(std::max(0.0f, 1 - u1)));
    queue.add(origin, direction,
              std::min(params.indirect_max_distance_m, box.exit(origin, direction)));
  }
}

// What a marched gather or lobe ray's end is judged by (gathered_radiance()).
struct RayEnds {
  const ObservationGrid& grid;
  const std::vector<render::PointLight>& lights;
  float margin;  // a hit this close to a light's proxy lies on it, or in a voxel it shares
  float saturated_radiance;
  const ContinuedPlane& plane;  // met beyond the reconstruction's box
  float max_distance_m;
};

// The ends of the rays from `grid`'s voxels under `lights`.
RayEnds ray_ends(const ObservationGrid& grid, const std::vector<render::PointLight>& lights,
                 const LightTransportParams& params, const ContinuedPlane& plane) {
  return {.grid = grid,
          .lights = lights,
          .margin = 2 * float(grid.params().voxel_size_m),
          .saturated_radiance = params.saturated_radiance,
          .plane = plane,
          .max_distance_m = params.indirect_max_distance_m};
}

// The radiance marched gather ray `ray` brings: none where it met a light's proxy or a clipped
// surface (their light is direct) or left the reconstruction, unless it then meets the continued
// plane within the rays' reach; false where it is unknown (a back face, a surface never
// observed), which is not counted.
bool gathered_radiance(const fusion::RayQueue& queue, int ray, const RayEnds& ends,
                       ObservationGrid::BlockCache& blocks, Eigen::Vector3f& radiance) {
  const fusion::MarchEnd& hit = queue.end(ray);
  if (hit.back_face) return false;
  radiance = Eigen::Vector3f::Zero();
  const Eigen::Vector3f& direction = queue.direction(ray);
  if (!(hit.t > 0)) {
    const float t = ends.plane.hit(queue.origin(ray), direction);
    if (t > queue.t_max(ray) && t <= ends.max_distance_m)
      radiance = ends.plane.radiance(queue.origin(ray) + t * direction, ends.lights);
    return true;
  }
  const Eigen::Vector3f h = queue.origin(ray) + direction * hit.t;
  if (!on_light(ends.lights, h, ends.margin) &&
      !hit_radiance(ends.grid, h, direction, queue.voxel_m(), blocks, radiance))
    return false;
  if (!(radiance.maxCoeff() < ends.saturated_radiance)) radiance = Eigen::Vector3f::Zero();
  return true;
}

// Queues `rays` rays from p (unit normal n) drawn from eq. (3)'s lobe for the view along unit
// wo (towards the viewer): half vectors by Walter's sampling (render/ward_sampling.h), each
// mirroring wo, stratified by ShiftedR2(hash); those below the surface are not queued. Returns
// how many were.
int queue_lobe_rays(fusion::RayQueue& queue, int rays, const Eigen::Vector3f& p,
                    const Eigen::Vector3f& n, const Eigen::Vector3f& wo, float alpha,
                    std::uint64_t hash, const LightTransportParams& params, const WorldBox& box) {
  const Eigen::Vector3f origin = p + params.ray_offset_m * n;
  const ShiftedR2 sequence(hash);
  int queued = 0;
  for (int k = 0; k < rays; ++k) {
    const Eigen::Vector2f u = sequence(float(k));
    const Eigen::Vector3f h = render::sample_ward_half_vector(n, alpha, u.x(), u.y());
    const Eigen::Vector3f wi = (2 * wo.dot(h) * h - wo).normalized();
    if (!(n.dot(wi) > 0)) continue;
    queue.add(origin, wi, std::min(params.indirect_max_distance_m, box.exit(origin, wi)));
    ++queued;
  }
  return queued;
}

// What a slot's MirrorSample remembers of the observation its ray was cast for: frame + 1 (0: no
// ray yet), so a newer observation in the slot is told apart.
std::uint32_t mirror_tag(const Observation& observation) { return observation.frame() + 1; }

// Lobe rays per stored observation: eq. (7) takes a median over a voxel's observations, which
// averages their one ray each. (Per re-rendered pixel: LightTransport::kPixelLobeRays.)
constexpr int kObservationLobeRays = 1;

// The mean radiance of `count` marched lobe rays from `first` (gathered_radiance()), NaN where
// none is known.
Eigen::Vector3f lobe_radiance(const fusion::RayQueue& queue, int first, int count,
                              const RayEnds& ends, ObservationGrid::BlockCache& blocks) {
  Eigen::Vector3f sum = Eigen::Vector3f::Zero(), radiance;
  int known = 0;
  for (int ray = first; ray < first + count; ++ray)
    if (gathered_radiance(queue, ray, ends, blocks, radiance)) {
      sum += radiance;
      ++known;
    }
  return known > 0 ? Eigen::Vector3f(sum / float(known)) : Eigen::Vector3f::Constant(NAN);
}

}  // namespace

const char* indirect_specular_name(IndirectSpecular mode) {
  switch (mode) {
    case IndirectSpecular::sky:
      return "sky";
    case IndirectSpecular::mirror:
      return "mirror";
    default:
      return "off";
  }
}

IndirectSpecular parse_indirect_specular(const std::string& name) {
  for (const IndirectSpecular mode :
       {IndirectSpecular::off, IndirectSpecular::sky, IndirectSpecular::mirror})
    if (name == indirect_specular_name(mode)) return mode;
  throw Error("indirect specular", name, "must be off, sky or mirror");
}

LightTransport::LightTransport(const LightTransportParams& params, std::size_t voxel_capacity,
                               int observations_per_voxel)
    : params_(params) {
  const auto positive = [](int value, const char* field) {
    if (value < 1) throw Error("light transport", field, "must be >= 1");
  };
  positive(params.shadow_refresh_frames, "shadow_refresh_frames");
  positive(params.indirect_rays, "indirect_rays");
  positive(params.indirect_rays_per_frame, "indirect_rays_per_frame");
  positive(params.indirect_refresh_frames, "indirect_refresh_frames");
  positive(params.indirect_every_frames, "indirect_every_frames");
  if (params.indirect_rays > 65535)
    throw Error("light transport", "indirect_rays", "must be <= 65535");
  if (params.indirect_min_rays < 0 || params.indirect_min_rays > params.indirect_rays)
    throw Error("light transport", "indirect_min_rays", "must be in [0, indirect_rays]");
  if (!(params.ray_offset_m >= 0 && std::isfinite(params.ray_offset_m)))
    throw Error("light transport", "ray_offset_m", "must be finite and >= 0");
  if (!(params.shadow_test_ratio >= 1 && params.shadow_test_gain >= 1))
    throw Error("light transport", "shadow_test_ratio, shadow_test_gain", "must be >= 1");
  if (!(params.shadow_test_sigmas >= 0 && std::isfinite(params.shadow_test_sigmas)))
    throw Error("light transport", "shadow_test_sigmas", "must be finite and >= 0");
  if (!(params.shadow_test_skip_m >= 0 && params.shadow_test_margin_m >= 0))
    throw Error("light transport", "shadow_test_skip_m, shadow_test_margin_m", "must be >= 0");
  if (!(params.indirect_max_distance_m > 0))
    throw Error("light transport", "indirect_max_distance_m", "must be > 0");
  positive(params.unseen_memory, "unseen_memory");
  if (params.indirect_scale_min_samples < 1 ||
      std::size_t(params.indirect_scale_min_samples) > kIndirectScaleSamples)
    throw Error("light transport", "indirect_scale_min_samples", "must be in [1, 1024]");
  if (!(params.indirect_scale_max > 0 && std::isfinite(params.indirect_scale_max)))
    throw Error("light transport", "indirect_scale_max", "must be finite and > 0");
  if (!(params.unseen_fit.min_leverage >= 1))
    throw Error("light transport", "unseen_fit.min_leverage", "must be >= 1");
  if (!(params.unseen_fit.min_share >= 0))
    throw Error("light transport", "unseen_fit.min_share", "must be >= 0");
  // No pools without shadows or the gather: lighting() answers from the parameters alone.
  if (!params_.shadows && !params_.indirect) return;
  lit_ = make_pool<LightMask>(voxel_capacity, "light transport visibility");
  shadow_cast_ = make_pool<bool>(voxel_capacity, "light transport visibility");
  occluded_ = make_pool<LightMask>(voxel_capacity, "light transport visibility");
  indirect_sum_ = make_pool<Eigen::Vector3f>(voxel_capacity, "light transport indirect");
  indirect_rays_ = make_pool<std::uint16_t>(voxel_capacity, "light transport indirect");
  indirect_next_ = make_pool<std::uint32_t>(voxel_capacity, "light transport indirect");
  indirect_ = make_pool<Eigen::Vector3f>(voxel_capacity, "light transport indirect");
  indirect_estimated_ = make_pool<bool>(voxel_capacity, "light transport indirect");
  if (mirrors())
    mirror_ = make_pool<MirrorSample>(voxel_capacity * std::size_t(observations_per_voxel),
                                      "light transport mirror rays");
}

ShadowRays queue_shadow_rays(fusion::RayQueue& queue, const fusion::TsdfVolume& volume,
                             const std::vector<render::PointLight>& lights,
                             const Eigen::Vector3f& p, const Eigen::Vector3f& n, float offset_m) {
  ShadowRays rays{.first = queue.size()};
  for_each_shadow_ray(volume, lights, p, n, offset_m,
                      [&](const Eigen::Vector3f& origin, const Eigen::Vector3f& direction,
                          float t_max, std::size_t light) {
                        queue.add(origin, direction, t_max);
                        rays.queued |= LightMask{1} << light;
                      });
  return rays;
}

LightMask true_shadow_mask(const render::EmbreeScene& scene, const fusion::TsdfVolume& volume,
                           const std::vector<render::PointLight>& lights, const Eigen::Vector3f& p,
                           const Eigen::Vector3f& n, float offset_m) {
  LightMask mask = kAllLights;
  for_each_shadow_ray(volume, lights, p, n, offset_m,
                      [&](const Eigen::Vector3f& origin, const Eigen::Vector3f& direction,
                          float t_max, std::size_t light) {
                        if (scene.occluded(origin, direction, t_max))
                          mask &= ~(LightMask{1} << light);
                      });
  return mask;
}

LightMask grazing_lights(const fusion::BlockOccupancy& occupancy, const fusion::TsdfVolume& volume,
                         const std::vector<render::PointLight>& lights, const Eigen::Vector3f& p,
                         const Eigen::Vector3f& n, LightMask lit,
                         const LightTransportParams& params) {
  fusion::TsdfSampler sampler(volume, &occupancy);
  LightMask grazing = 0;
  for_each_shadow_ray(
      volume, lights, p, n, params.ray_offset_m,
      [&](const Eigen::Vector3f& origin, const Eigen::Vector3f& direction, float t_max,
          std::size_t light) {
        if (!(lit >> light & 1)) return;
        // Through the blocks along the ray, across the empty regions in one step each.
        for (float t = params.shadow_test_skip_m; t < t_max - params.shadow_test_margin_m;) {
          const Eigen::Vector3f q = origin + direction * t;
          float sdf;
          if (sampler.nearest(q, sdf) != fusion::TsdfSampler::Sample::unallocated) {
            grazing |= LightMask{1} << light;
            return;
          }
          Eigen::Vector3f low, high;
          sampler.empty_box(q, low, high);
          t += std::max(fusion::box_exit(q, direction, low, high), 0.0f) + kGrazingStepM;
        }
      });
  return grazing;
}

LightMask shadow_mask(const fusion::RayQueue& queue, const ShadowRays& rays) {
  LightMask mask = kAllLights;
  int ray = rays.first;
  for (LightMask queued = rays.queued; queued != 0; queued &= queued - 1, ++ray) {
    const fusion::MarchEnd& end = queue.end(ray);
    if (end.t > 0 || end.back_face) mask &= ~(queued & -queued);
  }
  return mask;
}

LightMask shadow_mask(fusion::RayQueue& queue, const fusion::TsdfVolume& volume,
                      const std::vector<render::PointLight>& lights, const Eigen::Vector3f& p,
                      const Eigen::Vector3f& n, float offset_m) {
  queue.clear();
  const ShadowRays rays = queue_shadow_rays(queue, volume, lights, p, n, offset_m);
  queue.march();
  return shadow_mask(queue, rays);
}

void LightTransport::update_shadows(const ObservationGrid& grid, const fusion::TsdfVolume& volume,
                                    const fusion::BlockOccupancy& occupancy,
                                    const std::vector<render::PointLight>& lights, int frame) {
  if (!params_.shadows) return;
  due_.clear();
  for (const VisibleVoxel& seen : grid.visible())
    if (grid.has_surface(seen.voxel) &&
        (!shadow_cast_[seen.voxel] || (seen.voxel + frame) % params_.shadow_refresh_frames == 0))
      due_.push_back(seen.voxel);
  parallel_for_chunks(due_.size(), kVoxelsPerQueue, [&](std::size_t begin, std::size_t end) {
    fusion::RayQueue queue(volume, &occupancy);
    std::array<ShadowRays, kVoxelsPerQueue> rays;
    for (std::size_t batch = begin; batch < end; batch += kVoxelsPerQueue) {
      const std::size_t batch_end = std::min(end, batch + kVoxelsPerQueue);
      if (true_scene_) {
        for (std::size_t i = batch; i < batch_end; ++i) {
          lit_[due_[i]] = true_shadow_mask(*true_scene_, volume, lights, grid.position(due_[i]),
                                           grid.normal(due_[i]), params_.ray_offset_m);
          shadow_cast_[due_[i]] = true;
        }
        continue;
      }
      queue.clear();
      for (std::size_t i = batch; i < batch_end; ++i)
        rays[i - batch] = queue_shadow_rays(queue, volume, lights, grid.position(due_[i]),
                                            grid.normal(due_[i]), params_.ray_offset_m);
      queue.march();
      for (std::size_t i = batch; i < batch_end; ++i) {
        lit_[due_[i]] = shadow_mask(queue, rays[i - batch]);
        shadow_cast_[due_[i]] = true;
      }
    }
  });
}

void LightTransport::update_indirect(const ObservationGrid& grid, const fusion::TsdfVolume& volume,
                                     const fusion::BlockOccupancy& occupancy,
                                     const std::vector<render::PointLight>& lights, int frame) {
  if (!params_.indirect) return;
  const int n = params_.indirect_rays;
  due_.clear();
  for (const VisibleVoxel& seen : grid.visible())
    if (grid.has_surface(seen.voxel) &&
        (seen.voxel + frame) % (indirect_rays_[seen.voxel] < n ? params_.indirect_every_frames
                                                               : params_.indirect_refresh_frames) ==
            0)
      due_.push_back(seen.voxel);
  if (true_indirect_) {
    // Thousands of rays per voxel: small chunks keep the threads even.
    parallel_for_chunks(due_.size(), 4, [&](std::size_t begin, std::size_t end) {
      for (std::size_t i = begin; i < end; ++i) {
        const int v = due_[i];
        if (indirect_rays_[v] == n) continue;  // computed once
        const Eigen::Vector3f& normal = grid.normal(v);
        indirect_sum_[v] =
            true_indirect_->indirect_irradiance(grid.position(v) + params_.ray_offset_m * normal,
                                                normal, kTrueIndirectPaths, std::uint64_t(v)) *
            (float(n) / float(M_PI));
        indirect_rays_[v] = std::uint16_t(n);
        indirect_[v] = indirect_sum_[v] * (float(M_PI) / float(n));
        indirect_estimated_[v] = true;
      }
    });
    return;
  }
  const WorldBox box(occupancy, volume);
  const RayEnds ends = ray_ends(grid, lights, params_, plane_);
  parallel_for_chunks(due_.size(), kVoxelsPerQueue, [&](std::size_t begin, std::size_t end) {
    fusion::RayQueue queue(volume, &occupancy);
    ObservationGrid::BlockCache blocks;
    std::array<int, kVoxelsPerQueue> ray_count;
    for (std::size_t batch = begin; batch < end; batch += kVoxelsPerQueue) {
      const std::size_t batch_end = std::min(end, batch + kVoxelsPerQueue);
      queue.clear();
      for (std::size_t i = batch; i < batch_end; ++i) {
        const int v = due_[i];
        ray_count[i - batch] = indirect_rays_[v] < n ? params_.indirect_rays_per_frame : 1;
        queue_gather_rays(grid, v, ray_count[i - batch], params_, box, indirect_next_[v], queue);
      }
      queue.march();
      // The rays in the order they were queued: each voxel's sum adds them in its sequence's
      // order.
      int ray = 0;
      for (std::size_t i = batch; i < batch_end; ++i) {
        const int v = due_[i];
        for (int k = 0; k < ray_count[i - batch]; ++k, ++ray) {
          Eigen::Vector3f radiance;
          if (!gathered_radiance(queue, ray, ends, blocks, radiance)) continue;
          if (indirect_rays_[v] < n) {
            indirect_sum_[v] += radiance;
            ++indirect_rays_[v];
          } else {  // a moving average over the latest n
            indirect_sum_[v] += radiance - indirect_sum_[v] / float(n);
          }
        }
      }
    }
  });
  estimate_indirect(grid);
}

void LightTransport::update_mirrors(const ObservationGrid& grid, const fusion::TsdfVolume& volume,
                                    const fusion::BlockOccupancy& occupancy,
                                    const std::vector<render::PointLight>& lights,
                                    std::span<const int> voxels,
                                    const std::function<float(int)>& alpha) {
  if (!mirrors()) return;
  const WorldBox box(occupancy, volume);
  const RayEnds ends = ray_ends(grid, lights, params_, plane_);
  parallel_for_chunks(voxels.size(), kVoxelsPerQueue, [&](std::size_t begin, std::size_t end) {
    fusion::RayQueue queue(volume, &occupancy);
    ObservationGrid::BlockCache blocks;
    struct Cast {
      std::size_t slot;
      int first, count;
    };
    std::vector<Cast> casts;
    for (std::size_t batch = begin; batch < end; batch += kVoxelsPerQueue) {
      queue.clear();
      casts.clear();
      for (std::size_t i = batch; i < std::min(end, batch + kVoxelsPerQueue); ++i) {
        const int v = voxels[i];
        const float lobe_alpha = alpha(v);
        if (!(lobe_alpha > 0)) continue;
        const Observation* observations = grid.observations(v);
        const Eigen::Vector3f& normal = grid.normal(v);
        for (int k = 0; k < grid.observation_count(v); ++k) {
          const std::size_t slot = grid.first_slot(v) + std::size_t(k);
          const std::uint32_t tag = mirror_tag(observations[k]);
          if (mirror_[slot].tag == tag) continue;
          mirror_[slot] = {.tag = tag};
          const Eigen::Vector3f view = observations[k].direction();
          if (!(normal.dot(view) > 0)) continue;
          const int first = queue.size();
          const std::uint64_t hash =
              mix(params_.seed ^ place_hash(grid.voxel_coordinates(v)) ^ std::uint64_t(tag) << 32);
          const int count = queue_lobe_rays(queue, kObservationLobeRays, grid.position(v), normal,
                                            view, lobe_alpha, hash, params_, box);
          casts.push_back({slot, first, count});
        }
      }
      queue.march();
      for (const Cast& cast : casts) {
        const Eigen::Vector3f radiance = lobe_radiance(queue, cast.first, cast.count, ends, blocks);
        if (!radiance.allFinite()) continue;
        MirrorSample& sample = mirror_[cast.slot];
        for (int c = 0; c < 3; ++c) sample.radiance[std::size_t(c)] = half_from_float(radiance[c]);
        sample.known = true;
      }
    }
  });
}

std::span<const Eigen::Vector3f> LightTransport::mirrored(
    const ObservationGrid& grid, int v, std::span<Eigen::Vector3f> radiance) const {
  const float scale = mirror_scale();
  // Scale 0 (no bounced light): every ray's radiance is 0, as the even sky's.
  if (!mirrors() || scale == 0) return {};
  const int count = grid.observation_count(v);
  const Observation* observations = grid.observations(v);
  for (int k = 0; k < count; ++k) {
    const MirrorSample& sample = mirror_[grid.first_slot(v) + std::size_t(k)];
    Eigen::Vector3f& out = radiance[std::size_t(k)];
    if (!sample.known || sample.tag != mirror_tag(observations[k])) {
      out = Eigen::Vector3f::Constant(NAN);
      continue;
    }
    for (int c = 0; c < 3; ++c) out[c] = scale * float_from_half(sample.radiance[std::size_t(c)]);
  }
  return radiance.first(std::size_t(count));
}

Eigen::Vector3f LightTransport::mirror_radiance(
    fusion::RayQueue& queue, const ObservationGrid& grid, const fusion::BlockOccupancy& occupancy,
    const fusion::TsdfVolume& volume, const std::vector<render::PointLight>& lights,
    const Eigen::Vector3f& p, const Eigen::Vector3f& n, const Eigen::Vector3f& wo, float alpha,
    ObservationGrid::BlockCache& blocks) const {
  queue.clear();
  Eigen::Vector3i bits;
  std::memcpy(bits.data(), p.data(), sizeof(float) * 3);
  const int count =
      queue_lobe_rays(queue, kPixelLobeRays, p, n, wo, alpha, mix(params_.seed ^ place_hash(bits)),
                      params_, WorldBox(occupancy, volume));
  queue.march();
  return lobe_radiance(queue, 0, count, ray_ends(grid, lights, params_, plane_), blocks) *
         mirror_scale();
}

void LightTransport::estimate_indirect(const ObservationGrid& grid) {
  const float voxel_size = float(grid.params().voxel_size_m);
  const int pool_size = params_.indirect_pooling ? 27 : 1;
  parallel_for_chunks(due_.size(), 64, [&](std::size_t begin, std::size_t end) {
    ObservationGrid::BlockCache blocks;
    std::array<int, 27> pool;  // the voxel alone, or its 3x3x3 neighbourhood
    for (std::size_t i = begin; i < end; ++i) {
      const int v = due_[i];
      pool[0] = v;
      if (params_.indirect_pooling)
        grid.find_voxels(grid.voxel_coordinates(v) - Eigen::Vector3i::Ones(), 3, pool.data(),
                         &blocks);
      const Eigen::Vector3f& p_v = grid.position(v);
      const Eigen::Vector3f& n_v = grid.normal(v);
      Eigen::Vector3f sum = Eigen::Vector3f::Zero();
      int rays = 0;
      for (int k = 0; k < pool_size; ++k) {
        const int u = pool[std::size_t(k)];
        if (u >= 0 && indirect_rays_[u] > 0 && grid.has_surface(u) &&
            pools_indirect_rays(p_v, n_v, grid.position(u), grid.normal(u), voxel_size)) {
          sum += indirect_sum_[u];
          rays += indirect_rays_[u];
        }
      }
      indirect_estimated_[v] = rays >= params_.indirect_min_rays && rays > 0;
      if (indirect_estimated_[v]) indirect_[v] = sum * (float(M_PI) / float(rays));
    }
  });
}

void LightTransport::fuse_unseen(int segment, const RadianceLine& line) {
  if (segment < 0) return;
  if (std::size_t(segment) >= unseen_.size()) unseen_.resize(std::size_t(segment) + 1);
  FusedLine& fused = unseen_[std::size_t(segment)];
  fused.frames = std::min(fused.frames + 1, params_.unseen_memory);
  const float weight = 1.0f / float(fused.frames);
  fused.line.slope += weight * (line.slope - fused.line.slope);
  fused.line.intercept += weight * (line.intercept - fused.line.intercept);
  fused.line.typical_irradiance +=
      weight * (line.typical_irradiance - fused.line.typical_irradiance);
}

void LightTransport::add_indirect_scale_samples(std::span<const float> samples) {
  if (!scales_gather()) return;
  for (const float sample : samples) {
    if (scale_samples_.size() < kIndirectScaleSamples) {
      scale_samples_.push_back(sample);
    } else {
      scale_samples_[scale_next_] = sample;
      scale_next_ = (scale_next_ + 1) % kIndirectScaleSamples;
    }
  }
  if (scale_samples_.size() < std::size_t(params_.indirect_scale_min_samples)) return;
  scale_scratch_ = scale_samples_;
  const float median = median_in_place(scale_scratch_);
  scale_ = std::clamp(median, 0.0f, params_.indirect_scale_max);
  // Robust to the samples of voxels whose reference does not hold (a texture, a shadow the fused
  // geometry misses).
  const float spread = robust_spread_in_place(scale_scratch_, median);
  indirect_error_ = median > 0 ? spread / median : 0.0f;
}

PointLighting PointLightingQuery::operator()(const Eigen::Vector3f& p, const Eigen::Vector3f& n,
                                             const Eigen::Vector3f& eye, float alpha) {
  PointLighting result;
  const LightTransportParams& params = transport_.params();
  if (params.shadows)
    result.lit = transport_.true_scene()
                     ? true_shadow_mask(*transport_.true_scene(), volume_, lights_, p, n,
                                        params.ray_offset_m)
                     : shadow_mask(rays_, volume_, lights_, p, n, params.ray_offset_m);
  // The voxel holding the pixel's surface holds its indirect light and the lights the shadow
  // test dropped.
  const bool indirect = params.indirect || params.unseen;
  if (indirect || (params.shadows && params.shadow_test))
    if (const int v = observed_voxel(grid_, p, float(volume_.params().voxel_size_m), blocks_);
        v >= 0) {
      result.lit &= ~transport_.occluded(v);
      if (indirect) {
        const PointLighting voxel = transport_.lighting(v, grid_.segment(v));
        result.indirect = voxel.indirect;
        result.indirect_radiance = voxel.indirect_radiance;
      }
    }
  if (transport_.mirrors() && alpha > 0) {
    const Eigen::Vector3f view = (eye - p).normalized();
    if (n.dot(view) > 0) {
      const Eigen::Vector3f radiance = transport_.mirror_radiance(
          rays_, grid_, occupancy_, volume_, lights_, p, n, view, alpha, blocks_);
      if (radiance.allFinite()) result.indirect_radiance = radiance;
    }
  }
  return result;
}

}  // namespace glint::reflectance
