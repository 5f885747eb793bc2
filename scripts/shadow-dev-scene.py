#!/usr/bin/env python3
"""Development scenes for the pipeline's shadows: objects and lights of their own on the camera
path of a rendered bunnies sequence, so that no choice about shadows is made on the evaluation
scenes (bunnies, office, heldout).
  shadow-dev          a teapot, a cow, Suzanne and a box on a grey floor under three lights
  shadow-dev-texture  the same with a textured floor (facade) and box (onyx)
Usage: shadow-dev-scene.py NAME BUNNIES_SEQ/scene.json DATA OUT.json [OUT_LIGHTS.json]
then   glint render OUT.json -o seq [--no-shadows]
       glint reconstruct seq --lights OUT_LIGHTS.json --gt-poses ...
OUT_LIGHTS.json holds the scene's true lights in the format of `glint lights`."""
import json
import math
import sys

SCENES = ("shadow-dev", "shadow-dev-texture")


def rotation_about_y(degrees):
    half = math.radians(degrees) / 2
    return [0.0, math.sin(half), 0.0, math.cos(half)]


def scene_object(object_id, name, shape, size, position, degrees, kd, ks, alpha, mesh=None,
                 texture=None, texture_scale_m=1.0):
    material = {"kd": kd, "ks": ks, "alpha": alpha, "texture_scale_m": texture_scale_m}
    if texture:
        material["kd_texture"] = texture
    obj = {"id": object_id, "name": name, "shape": shape, "size": size,
           "transform": {"position": position, "quaternion": rotation_about_y(degrees)},
           "material": material}
    if mesh:
        obj["mesh"] = mesh
    return obj


def main():
    if len(sys.argv) not in (5, 6) or sys.argv[1] not in SCENES:
        sys.exit(__doc__)
    name, base_path, data, out = sys.argv[1:5]
    with open(base_path) as f:
        scene = json.load(f)
    meshes, textures = data + "/meshes/", data + "/textures/"
    textured = name == "shadow-dev-texture"
    grey = [0.6, 0.6, 0.6]
    scene["objects"] = [
        scene_object(1, "floor", "plane", [8.0, 1.0, 8.0], [0, 0, 0], 0,
                     grey if textured else [0.45, 0.42, 0.38], [0.05] * 3, 0.25,
                     texture=textures + "facade/albedo.jpg" if textured else None),
        scene_object(2, "teapot", "mesh", [1.2] * 3, [1.1, 0.0, 0.5], 30, [0.60, 0.20, 0.15],
                     [0.15] * 3, 0.08, mesh=meshes + "teapot.obj"),
        scene_object(3, "cow", "mesh", [1.3] * 3, [-0.9, 0.0, -0.8], 120, [0.70, 0.70, 0.60],
                     [0.08] * 3, 0.15, mesh=meshes + "spot.obj"),
        scene_object(4, "suzanne", "mesh", [1.0] * 3, [-0.5, 0.0, 1.2], -40, [0.20, 0.35, 0.60],
                     [0.20] * 3, 0.06, mesh=meshes + "suzanne.obj"),
        scene_object(5, "box", "box", [0.6, 0.8, 0.6], [0.5, 0.0, -1.3], 25,
                     grey if textured else [0.25, 0.50, 0.20], [0.10] * 3, 0.12,
                     texture=textures + "onyx/albedo.jpg" if textured else None,
                     texture_scale_m=0.5 if textured else 1.0),
    ]
    scene["lights"] = [
        {"intensity": [10.0] * 3, "position": [0.6, 2.4, -0.4], "proxy_radius_m": 0.05},
        {"intensity": [7.0, 7.5, 8.0], "position": [-2.3, 1.8, 1.2], "proxy_radius_m": 0.05},
        {"intensity": [6.0, 5.5, 4.5], "position": [2.0, 1.5, -2.1], "proxy_radius_m": 0.05},
    ]
    with open(out, "w") as f:
        json.dump(scene, f, indent=1)
    if len(sys.argv) == 6:
        lights = [{"position": light["position"], "intensity": light["intensity"],
                   "radius_m": light["proxy_radius_m"]} for light in scene["lights"]]
        with open(sys.argv[5], "w") as f:
            json.dump({"lights": lights}, f, indent=1)


if __name__ == "__main__":
    main()
