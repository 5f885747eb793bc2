#pragma once
// scene.json <-> render::Scene. The format (docs/reflectance.md, "scene.json", documents it):
//   {
//     "objects": [{"name", "id", "shape": "mesh|box|sphere|plane", "mesh": "bunny.obj",
//                  "size": [x, y, z],
//                  "transform": {"position": [x, y, z],
//                                "rotation": {"axis": [x, y, z], "angle_deg": a}
//                                 or "quaternion": [qx, qy, qz, qw]},
//                  "material": {"kd": [r, g, b] or v, "ks": [r, g, b] or v, "alpha": a,
//                               "kd_texture": "wood.png", "texture_scale_m": 1}}],
//     "lights": [{"position": [x, y, z], "intensity": [r, g, b] or v, "proxy_radius_m": r}],
//     "environment": {"path": "studio.hdr", "scale": 1, "rotation_deg": 0, "samples": 64},
//     "camera": {"intrinsics": {"width", "height", "fx", "fy", "cx", "cy"},
//                "exposure": 1, "sensor_noise": 0, "depth_noise": false},
//     "trajectory": [[tx, ty, tz, qx, qy, qz, qw], ...]         (camera-to-world, OpenCV axes)
//              or {"orbit": {"center": [x, y, z], "radius": r, "height": h, "frames": n,
//                            "revolutions": 1, "start_deg": 0}},
//     "fps": 30, "shadows": true, "bounces": 0, "indirect_samples": 32, "seed": 1
//   }
// Every key but "objects" and "trajectory" is optional with scene.h's defaults. Relative paths
// (meshes, textures, environment) resolve against the JSON file's folder; the Scene holds them
// resolved. Colours are linear RGB.
#include <string>

#include "render/scene.h"

namespace glint::render {

// Parses and validates a scene: throws glint::Error(path, element, reason) for malformed JSON,
// a missing or mistyped key, an unknown shape, alpha <= 0, kd + ks > 1 in any channel (a
// homogeneous material that reflects more than it receives), non-positive sizes, invalid
// intrinsics, an empty trajectory, and a mesh, texture or environment file that does not exist.
// Orbit trajectories are expanded into poses here.
Scene read_scene_json(const std::string& path);

// Writes the scene atomically: every field, the trajectory as explicit poses, file paths made
// absolute (against the current folder), so the copy inside a sequence folder still works.
void write_scene_json(const std::string& path, const Scene& scene);

}  // namespace glint::render
