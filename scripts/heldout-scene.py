#!/usr/bin/env python3
"""Held-out scenes for the reflectance evaluation: a built-in scene's geometry, lights and camera
path with materials no training choice was made on.
  heldout        bunnies with a blue-grey floor, a glossy dark-green bunny, a white one and a
                 copper one (a metal's tinted highlight); made before the training materials'
                 colours were changed.
  heldout-cubes  cubes with a warm light-grey floor and light-grey, purple, pale-pink, dark-grey,
                 olive and silver cubes: matte near-greys, which the training materials drew
                 rarely; made before any network was trained on the near-grey set.
  heldout-office office with pale green walls, a blue-grey floor and untextured furniture and
                 objects; made before the gather's scene scale (--indirect-scale) was run on it.
`heldout-scene.py base NAME` prints NAME's base scene. Otherwise reads the scene.json of the
rendered base sequence and writes the edited copy; then
  glint render OUT.json -o seq-heldout --no-shadows
  glint reconstruct seq-heldout --lights lights-bunnies.json --gt-poses --gt-segmentation ...
(the lights are the base scene's, so its estimated lights.json serves).
usage: heldout-scene.py base {heldout,heldout-cubes,heldout-office}
       heldout-scene.py {heldout,heldout-cubes,heldout-office} BASE_SEQ/scene.json OUT.json"""
import json
import sys

# held-out scene -> (base scene, {object id -> (name, kd, ks, alpha)})
SCENES = {
    "heldout": ("bunnies", {
        1: ("floor", [0.30, 0.35, 0.40], [0.06] * 3, 0.20),
        2: ("dark green bunny", [0.05, 0.20, 0.08], [0.25] * 3, 0.04),
        3: ("white bunny", [0.80, 0.80, 0.80], [0.10] * 3, 0.15),
        4: ("copper bunny", [0.15, 0.06, 0.03], [0.60, 0.35, 0.20], 0.12),
    }),
    "heldout-cubes": ("cubes", {
        1: ("floor", [0.60, 0.58, 0.55], [0.03] * 3, 0.25),
        2: ("light grey cube", [0.65, 0.65, 0.65], [0.08] * 3, 0.10),
        3: ("purple cube", [0.30, 0.08, 0.40], [0.20] * 3, 0.06),
        4: ("pale pink cube", [0.80, 0.55, 0.50], [0.05] * 3, 0.20),
        5: ("dark grey cube", [0.15, 0.15, 0.15], [0.30] * 3, 0.05),
        6: ("olive cube", [0.30, 0.30, 0.05], [0.10] * 3, 0.15),
        7: ("silver cube", [0.10, 0.10, 0.10], [0.50] * 3, 0.10),
    }),
    "heldout-office": ("office", {
        1: ("floor", [0.25, 0.28, 0.32], [0.04] * 3, 0.20),
        2: ("back wall", [0.55, 0.65, 0.55], [0.02] * 3, 0.30),
        3: ("left wall", [0.55, 0.65, 0.55], [0.02] * 3, 0.30),
        4: ("right wall", [0.55, 0.65, 0.55], [0.02] * 3, 0.30),
        5: ("table", [0.45, 0.30, 0.20], [0.05] * 3, 0.10),
        6: ("spot", [0.75, 0.72, 0.70], [0.05] * 3, 0.20),
        7: ("teapot", [0.08, 0.10, 0.30], [0.20] * 3, 0.06),
        8: ("suzanne", [0.70, 0.60, 0.10], [0.10] * 3, 0.15),
        9: ("crate", [0.40, 0.35, 0.25], [0.02] * 3, 0.30),
        10: ("ball", [0.85, 0.85, 0.85], [0.05] * 3, 0.20),
        11: ("cabinet", [0.20, 0.25, 0.30], [0.15] * 3, 0.20),
    }),
}


def main():
    if len(sys.argv) == 3 and sys.argv[1] == "base" and sys.argv[2] in SCENES:
        print(SCENES[sys.argv[2]][0])
        return
    if len(sys.argv) != 4 or sys.argv[1] not in SCENES:
        sys.exit(__doc__)
    base, materials = SCENES[sys.argv[1]]
    with open(sys.argv[2]) as f:
        scene = json.load(f)
    ids = sorted(o["id"] for o in scene["objects"])
    if ids != sorted(materials):
        sys.exit(f"{sys.argv[2]}: object ids {ids}, not {base}' {sorted(materials)}")
    for obj in scene["objects"]:
        name, kd, ks, alpha = materials[obj["id"]]
        obj["name"] = name
        obj["material"] = {"kd": kd, "ks": ks, "alpha": alpha}
    with open(sys.argv[3], "w") as f:
        json.dump(scene, f, indent=1)


if __name__ == "__main__":
    main()
