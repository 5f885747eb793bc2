#!/usr/bin/env python3
"""The held-out scene of 2026-11-29's eighth session (docs/reflectance/history.md): bunnies'
geometry, lights and camera path with materials no training choice was made on: a blue-grey
floor, a glossy dark-green bunny, a white one and a copper one (a metal's tinted highlight).
Reads the scene.json of a rendered bunnies sequence, writes the edited copy; then
  glint render OUT.json -o seq-heldout --no-shadows
  glint reconstruct seq-heldout --lights lights-bunnies.json --gt-poses --gt-segmentation ...
(the lights are bunnies', so bunnies' estimated lights.json serves).
usage: heldout-scene.py BUNNIES_SEQ/scene.json OUT.json"""
import json
import sys

# object id -> name, kd, ks, alpha
MATERIALS = {
    1: ("floor", [0.30, 0.35, 0.40], [0.06] * 3, 0.20),
    2: ("dark green bunny", [0.05, 0.20, 0.08], [0.25] * 3, 0.04),
    3: ("white bunny", [0.80, 0.80, 0.80], [0.10] * 3, 0.15),
    4: ("copper bunny", [0.15, 0.06, 0.03], [0.60, 0.35, 0.20], 0.12),
}


def main():
    if len(sys.argv) != 3:
        sys.exit(__doc__)
    with open(sys.argv[1]) as f:
        scene = json.load(f)
    ids = sorted(o["id"] for o in scene["objects"])
    if ids != sorted(MATERIALS):
        sys.exit(f"{sys.argv[1]}: object ids {ids}, not bunnies' {sorted(MATERIALS)}")
    for obj in scene["objects"]:
        name, kd, ks, alpha = MATERIALS[obj["id"]]
        obj["name"] = name
        obj["material"] = {"kd": kd, "ks": ks, "alpha": alpha}
    with open(sys.argv[2], "w") as f:
        json.dump(scene, f, indent=1)


if __name__ == "__main__":
    main()
