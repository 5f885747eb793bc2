#pragma once
// ContinuedPlane: the largest plane of the reconstruction (mostly its floor), continued beyond
// what the camera saw. A gather or lobe ray that leaves the reconstruction counts as dark, yet on
// a floor scanned from one side the rays aimed at the floor behind the camera meet lit floor.
// Beyond the reconstruction's box such a ray meets the plane instead and brings the plane's
// diffuse radiance under the lights there, unshadowed: nothing is known out there
// (docs/decisions.md, "The largest plane continues beyond the reconstruction").
#include <Eigen/Core>
#include <functional>
#include <limits>
#include <vector>

#include "reflectance/observation_grid.h"
#include "render/scene.h"

namespace glint::reflectance {

struct ContinuedPlane {
  Eigen::Vector3f normal = Eigen::Vector3f::Zero();  // unit, towards the side the camera saw
  float offset = 0;                                  // normal . x = offset on the plane
  Eigen::Vector3f albedo = Eigen::Vector3f::Zero();  // its segment's kd

  bool known() const { return normal.squaredNorm() > 0; }
  // The t > 0 at which origin + t * direction meets the plane from its front side; infinity
  // where it does not (not known, parallel, moving away, or starting behind it).
  float hit(const Eigen::Vector3f& origin, const Eigen::Vector3f& direction) const {
    const float approach = -normal.dot(direction), height = normal.dot(origin) - offset;
    return approach > 0 && height > 0 ? height / approach : std::numeric_limits<float>::infinity();
  }
  // Its diffuse radiance at p on it: albedo / pi times the lights' irradiance, sum I cos / d^2
  // (eq. (6) without its specular term).
  Eigen::Vector3f radiance(const Eigen::Vector3f& p,
                           const std::vector<render::PointLight>& lights) const;
};

// Of the segments whose surface voxels lie on a plane (RMS distance to their least-squares plane
// at most `thickness_m`, their mean normal within 25 degrees of its normal) and whose albedo
// `albedo(segment)` knows (all finite), the one with the most voxels; not known() where none is.
ContinuedPlane largest_plane(const ObservationGrid& grid, float thickness_m,
                             const std::function<Eigen::Vector3f(int)>& albedo);

}  // namespace glint::reflectance
