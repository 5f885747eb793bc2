#pragma once
// HemiImages (paper 1 §3.6): a voxel's observations as a small image over the hemisphere
// around its normal, the input of the HemiCNN. Directions are rotated so the normal is +z,
// projected to the unit disk and scaled to pixel coordinates [0, size-1]^2; every pixel takes
// the colour of the nearest projected observation (nearest-neighbour fill).
//  - parabolic (paper 1, default): u = x / (1 + z), v = y / (1 + z) (keeps flat angles apart)
//  - orthographic (Kim et al. 2017, the unmodified HemiCNN): u = x, v = y
#include <Eigen/Core>
#include <string>
#include <vector>

#include "reflectance/light_incidence.h"
#include "reflectance/observation.h"
#include "render/scene.h"

namespace glint::reflectance {

enum class HemiProjection { parabolic, orthographic };

// What a hemi-image's pixels hold:
//  - radiance (paper 1): the observed linear radiance; the network must guess the lighting
//  - reflectance (glint's): radiance times reflectance_scale (reflectance/light_incidence.h),
//    pi over the point lights' irradiance at the voxel, so that a Lambertian surface shows its
//    albedo kd in every pixel whatever the lights, and a lobe rises above it
enum class HemiInput { radiance, reflectance };

// "parabolic" / "orthographic" and back; an unknown name -> glint::Error(where, "projection").
const char* hemi_projection_name(HemiProjection projection);
HemiProjection parse_hemi_projection(const std::string& name, const std::string& where);
// "radiance" / "reflectance" and back; an unknown name -> glint::Error(where, "input").
const char* hemi_input_name(HemiInput input);
HemiInput parse_hemi_input(const std::string& name, const std::string& where);

// Hemi-image sizes glint supports (pixels per side).
inline constexpr int kMinHemiImageSize = 3, kMaxHemiImageSize = 64;

struct HemiImageParams {
  int size = 15;  // pixels per side, in [kMinHemiImageSize, kMaxHemiImageSize]
  HemiProjection projection = HemiProjection::parabolic;
};

// A right-handed orthonormal frame (t, b, n) around unit normal n, continuous except at
// n = -z (Duff et al. 2017); rows of the returned matrix map world to local coordinates.
Eigen::Matrix3f local_frame(const Eigen::Vector3f& normal);

// Disk coordinates (u, v) in [-1, 1]^2 of a local direction with z >= 0.
Eigen::Vector2f project_to_disk(const Eigen::Vector3f& local_direction, HemiProjection projection);

// The per-channel scale of a voxel's hemi-image for `input`: one for radiance,
// reflectance_scale(lights, position, normal, lighting) (reflectance/light_incidence.h) for
// reflectance: the voxel's shadowed lights left out, its indirect irradiance added.
Eigen::Vector3f hemi_input_scale(HemiInput input, const std::vector<render::PointLight>& lights,
                                 const Eigen::Vector3f& position, const Eigen::Vector3f& normal,
                                 const PointLighting& lighting = {});

// Writes size*size*3 floats, channel-major (CHW) like the network's input, into `out`: each
// pixel the colour of its nearest observation times `scale` per channel (HemiInput).
// Observations below the surface (direction . normal <= 0) are ignored; with none left the
// image is black. At most the first 256 observations are used. No allocation.
void make_hemi_image(const Observation* observations, int count, const Eigen::Vector3f& normal,
                     const HemiImageParams& params, float* out,
                     const Eigen::Vector3f& scale = Eigen::Vector3f::Ones());

}  // namespace glint::reflectance
