"""Imports a glint scene.glb into Blender and renders one Cycles frame on the CPU: the check that
the export opens, lit by its lights, in a DCC tool (a benchmark step, never a test dependency).

  blender -b --python scripts/blender-render-glb.py -- scene.glb out.png [--samples 16]
      [--intrinsics fx,fy,cx,cy,width,height --world-to-camera m00,...,m33] [--exposure X]
      [--threads 2] [--no-shadows]

Without a pose the camera frames the whole model. With one it is glint's camera (as the viewer's
URL parameters, web/viewer/viewer.js): pinhole intrinsics in pixels and the world-to-camera
matrix in glint's world and OpenCV axes. The glTF importer runs with lighting mode "COMPAT"
(a point light of glTF intensity I candela irradiates I/d², glint's light units); the world is
black and the view transform "Standard" (linear radiance × exposure → sRGB, clipped), as glint's
re-renderings. Prints one JSON line: objects, lights, materials, render seconds.
"""
import argparse
import json
import math
import sys
import time

import bpy
import numpy
from mathutils import Matrix, Vector

# Debian 12's Blender 3.4 glTF importer still calls numpy.bool, which Debian 12's NumPy 1.24 no
# longer has (import fails in set_poly_smoothing); the alias it meant is the builtin bool.
if not hasattr(numpy, "bool"):
    numpy.bool = bool


def arguments():
    argv = sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else []
    parser = argparse.ArgumentParser(prog="blender -b --python blender-render-glb.py --")
    parser.add_argument("glb")
    parser.add_argument("png")
    parser.add_argument("--samples", type=int, default=16)
    parser.add_argument("--intrinsics")
    parser.add_argument("--world-to-camera")
    parser.add_argument("--exposure", type=float)
    parser.add_argument("--threads", type=int, default=2)
    parser.add_argument("--no-shadows", action="store_true",
                        help="lights cast no shadows (as glint's re-renderings)")
    return parser.parse_args(argv)


def numbers(text, count, name):
    values = [float(v) for v in text.split(",")]
    if len(values) != count:
        sys.exit(f"blender-render-glb: {name} needs {count} comma-separated numbers")
    return values


def main():
    args = arguments()
    bpy.ops.wm.read_factory_settings(use_empty=True)
    scene = bpy.context.scene
    bpy.ops.import_scene.gltf(filepath=args.glb, convert_lighting_mode="COMPAT")
    objects = list(scene.objects)
    meshes = [o for o in objects if o.type == "MESH"]
    lights = [o for o in objects if o.type == "LIGHT"]
    if not meshes:
        sys.exit(f"blender-render-glb: {args.glb} has no mesh")
    for light in lights:
        light.data.shadow_soft_size = 0  # glint's lights are points
        light.data.cycles.cast_shadow = not args.no_shadows

    # The exposure glint stored with the scene (scenes[0].extras.glint), unless given.
    exposure = args.exposure
    if exposure is None:
        exposure = float(scene.get("glint", {}).get("exposure", 1.0)) if "glint" in scene else 1.0

    width, height = 640, 480
    camera = bpy.data.objects.new("camera", bpy.data.cameras.new("camera"))
    scene.collection.objects.link(camera)
    scene.camera = camera
    camera.data.clip_start, camera.data.clip_end = 0.01, 100
    if args.intrinsics:
        fx, fy, cx, cy, width, height = numbers(args.intrinsics, 6, "--intrinsics")
        width, height = int(width), int(height)
        world_to_camera = Matrix([numbers(args.world_to_camera, 16, "--world-to-camera")[4 * r:4 * r + 4]
                                  for r in range(4)])
        # Blender's camera looks down −z with y up: camera-to-world · diag(1, −1, −1) in glint's
        # world, then into Blender's world through the imported root node (glTF node 0, which
        # turns glint's world into glTF's +Y up, with the importer's +Y up → +Z up).
        root = next(o for o in objects if o.parent is None and o.type == "EMPTY")
        gltf_to_blender = Matrix(((1, 0, 0, 0), (0, 0, -1, 0), (0, 1, 0, 0), (0, 0, 0, 1)))
        flip = Matrix.Diagonal((1, -1, -1, 1))
        camera.matrix_world = (root.matrix_world @ gltf_to_blender @ world_to_camera.inverted()
                               @ flip)
        camera.data.sensor_fit = "HORIZONTAL"
        camera.data.sensor_width = 36
        camera.data.lens = fx * 36 / width
        # Shifts are fractions of the larger image side; pixel centres at integer coordinates.
        camera.data.shift_x = (width / 2 - (cx + 0.5)) / max(width, height)
        camera.data.shift_y = ((cy + 0.5) - height / 2) / max(width, height)
        if abs(fx - fy) > 1e-6 * fx:
            print("blender-render-glb: fx != fy, Blender's camera uses fx", file=sys.stderr)
    else:
        corners = [o.matrix_world @ Vector(c) for o in meshes for c in o.bound_box]
        low = Vector([min(c[i] for c in corners) for i in range(3)])
        high = Vector([max(c[i] for c in corners) for i in range(3)])
        centre, radius = (low + high) / 2, (high - low).length / 2
        camera.location = centre + Vector((0, -1.8 * radius, 0.6 * radius))
        camera.rotation_euler = (centre - camera.location).to_track_quat("-Z", "Y").to_euler()
        camera.data.lens = 30

    world = bpy.data.worlds.new("black")
    world.color = (0, 0, 0)
    scene.world = world
    scene.render.engine = "CYCLES"
    scene.cycles.device = "CPU"
    scene.cycles.samples = args.samples
    scene.cycles.use_denoising = False
    scene.render.threads_mode = "FIXED"
    scene.render.threads = args.threads
    scene.render.resolution_x, scene.render.resolution_y = width, height
    scene.render.resolution_percentage = 100
    scene.view_settings.view_transform = "Standard"
    scene.view_settings.look = "None"
    scene.view_settings.exposure = math.log2(exposure)
    scene.render.image_settings.file_format = "PNG"
    scene.render.filepath = args.png
    start = time.perf_counter()
    bpy.ops.render.render(write_still=True)
    print(json.dumps({"glb": args.glb, "png": args.png, "meshes": len(meshes), "lights": len(lights),
                      "materials": len(bpy.data.materials), "samples": args.samples,
                      "width": width, "height": height, "exposure": exposure,
                      "render_s": round(time.perf_counter() - start, 2),
                      "blender": bpy.app.version_string}))


main()
