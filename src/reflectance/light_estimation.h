#pragma once
// Near-field point lights from the low-exposure light-capture sequence (paper 1 §3.2): per
// frame, pixels of luminance >= min_luminance are back-projected with their depth and the
// frame's ground-truth camera pose and grouped by mean shift (reflectance/light_capture.h); the
// per-frame candidates are fused over the sequence (LightFuser, min_frames). The paper gives no
// intensity; we measure it physically, per frame and light:
//
//   I = D^2 * sum_px L_px * omega_px,   L_px = pixel / exposure,   omega_px = cos^3(theta) / (fx
//   fy)
//
// (omega_px: the pixel's solid angle, theta its angle to the optical axis; D: the camera's
// distance to the light). A uniformly emitting sphere of radius r and radiance L has intensity
// L pi r^2 in every direction, exactly the renderer's light proxy (render/renderer.h), so this is
// exact for synthetic captures. Lamps are modelled as such spheres: the visible pixels lie on the
// camera-facing cap, on average 2r/3 in front of the centre, with r from the cluster's solid
// angle (sin of its half-angle = r / D); the estimate moves the centroid back by that amount
// (spherical_emitters = false keeps the centroid and uses each pixel's own distance, for flat
// emitters). A cluster touching the image border is a partial view and is not used. Per light
// the position is the pixel-weighted mean over its frames, the intensity the mean over its
// frames after dropping those further than a factor 2 from the median (gross outliers such as
// a partly occluded lamp; the median itself reads 12 % low on lamps a few pixels wide, whose
// pixel count jumps from frame to frame).
//
// Units: intensities are in the capture's radiance units (pixel / exposure) times m^2, i.e. a
// surface at distance d receives I / d^2 in the units of pixel / exposure. To compare with the
// main (material) sequence, divide its pixels by its own exposure too (scene.json camera.exposure
// for glint's synthetic sequences; the ratio of exposure times x gains for a real camera).
// Limits: 8-bit clipping makes a light's intensity a lower bound (a warning gives the clipped
// fraction; channels >= sRGB code 254 count as clipped); pixels without depth are skipped; every
// frame needs a ground-truth pose.
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "io/rgbd_sequence.h"
#include "reflectance/light_clustering.h"
#include "render/scene.h"

namespace glint::reflectance {

struct LightEstimationParams {
  // Linear luminance (Rec. 709) a pixel must reach, before dividing by the exposure. Built-in
  // captures (render::kLightCaptureExposure): proxies have luminance >= 0.37, lit surfaces
  // < 0.02 (measured over all three scenes).
  float min_luminance = 0.05f;
  // The capture's exposure; unset: scene.json camera.exposure in the sequence folder, else 1.
  std::optional<float> exposure;
  MeanShiftParams clustering;  // per-frame mean shift, bandwidth_m = 0.2
  double min_cluster_px = 4;   // smaller per-frame clusters are noise or glints
  LightFusionParams fusion;    // merge_radius_m = 0.3, min_frames = 3
  bool spherical_emitters = true;
  // A frame with more than this fraction of its pixels at min_luminance or above is no
  // low-exposure capture: there the lamps are a few bright spots, while a normally exposed
  // frame has most of its lit surfaces above the threshold, and mean shift over all of them would
  // run for hours. Such a frame is an error naming its colour image.
  double max_bright_fraction = 0.2;
};

// How well each estimated light is supported by the capture.
struct LightSupport {
  int frames = 0;                // frames that saw it (whole)
  double pixels = 0;             // bright pixels over those frames
  double position_spread_m = 0;  // RMS distance of the per-frame positions from the estimate
  double clipped_fraction = 0;   // of its pixels, those with a clipped channel
};

struct LightEstimate {
  // Position (world, metres), intensity (see Units above) and proxy_radius_m (the mean
  // sphere radius seen; a re-rendering draws a proxy of that size).
  std::vector<render::PointLight> lights;
  std::vector<LightSupport> support;  // parallel to lights
  std::string capture;                // the capture sequence's folder
  float exposure = 1;                 // the capture exposure the intensities are divided by
};

// scene.json's camera.exposure in `folder`, or 1 when the folder has no scene.json. Throws
// glint::Error naming scene.json when it is malformed or the exposure is not > 0.
float capture_exposure(const std::string& folder);

// Estimates the lights of `capture`, calling on_frame (may be empty) after each frame, possibly
// from several threads. Throws glint::Error naming the sequence when a frame has no
// ground-truth pose or the parameters are invalid, and the image file when a frame is unreadable.
// A capture in which no light passes the thresholds gives an empty estimate (and a warning).
LightEstimate estimate_lights(const io::RgbdSequence& capture,
                              const LightEstimationParams& params = {},
                              const std::function<void()>& on_frame = {});

// lights.json:
//   {"lights": [{"position": [x, y, z], "intensity": [r, g, b], "radius_m": r, "frames": n,
//                "pixels": n, "position_spread_m": s, "clipped_fraction": f}, ...],
//    "capture": "folder", "exposure": e}
// Written atomically; an estimate without support (lights taken from a scene.json) writes the
// LightSupport defaults. The reader needs "lights" with position and intensity (finite, intensity
// >= 0); the other keys are optional with LightSupport's defaults (radius_m: PointLight's).
// Throws glint::Error naming the file and the element (e.g. "lights[1].position") otherwise.
void write_lights_json(const std::string& path, const LightEstimate& estimate);
LightEstimate read_lights_json(const std::string& path);

}  // namespace glint::reflectance
