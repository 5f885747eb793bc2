#!/usr/bin/env python3
"""Summary of scripts/eval-light-transport.sh as Markdown: per scene and rendering (a: direct
light without shadows, b: with shadows, c: with shadows and indirect light), before (the paper's
image model), before-unseen (that and the segments' unseen light), after (shadows), indirect
(shadows and the gathered indirect light), scaled (that scaled by what unlit voxels show), tested
(that and the shadow test: the defaults), unseen (shadows and the unseen light) and
indirect-unseen (shadows, the gather and the unseen light), the averaged object L1 of
kd, refined kd, ks, alpha and the PSNR over the objects' pixels of kd, refined kd, RGB, refined
RGB; each b and c row's gap to a; and the per-stage milliseconds per frame of the timing runs
beside paper 1's GTX 1080 totals.
usage: light-transport-summary.py OUT"""
import glob
import json
import os
import sys

VARIANTS = ["before", "before-unseen", "after", "indirect", "scaled", "tested", "glossy", "mirror",
            "shrinkage", "unseen", "indirect-unseen"]
PAPER_TOTALS = {"2cm": {"cubes": 17.294, "bunnies": 25.023, "office": 29.763},
                "1cm": {"cubes": 23.919, "bunnies": 44.467, "office": 54.794}}
STAGES = ["geometry", "observations", "segmentation", "shadows", "indirect", "specular", "mirror",
          "albedo", "total"]
RENDERS = {"a": "direct, no shadows", "b": "direct, shadows", "c": "shadows + bounces"}


def load(out, name):
    path = os.path.join(out, name + ".json")
    return json.load(open(path)) if os.path.exists(path) else None


def quality(report):
    a = report["evaluation"]["average"]
    return {"kd L1": a["kd"]["l1"], "kd_ref L1": a["kd_ref"]["l1"], "ks L1": a["ks"]["l1"],
            "alpha L1": a["alpha"]["l1"], "kd PSNR": a["kd"]["psnr"],
            "kd_ref PSNR": a["kd_ref"]["psnr"], "rgb PSNR": a["rgb"]["psnr"],
            "rgb_ref PSNR": a["rgb_ref"]["psnr"]}


def main():
    out = sys.argv[1]
    scenes = sorted({os.path.basename(p).split("-")[0]
                     for p in glob.glob(os.path.join(out, "*-?-before.json"))})
    columns = ["kd L1", "kd_ref L1", "ks L1", "alpha L1", "kd PSNR", "kd_ref PSNR", "rgb PSNR",
               "rgb_ref PSNR"]
    lines = ["# Shadows and interreflections: reflectance quality", "",
             "glint's own segmentation, ground-truth poses, estimated lights, 2 cm observation "
             "voxels; averages over the objects of every 10th frame. PSNR over the objects' "
             "pixels (dB). `refined > unrefined`: refined-kd PSNR above the segment kd's.", "",
             "| scene | rendering | pipeline | " + " | ".join(columns) +
             " | refined > unrefined |", "|---" * (len(columns) + 4) + "|"]
    for scene in scenes:
        for r, title in RENDERS.items():
            for variant in VARIANTS:
                rep = load(out, f"{scene}-{r}-{variant}")
                if not (rep and rep.get("evaluation")):
                    continue
                q = quality(rep)
                cells = [f"{q[c]:.3f}" if "L1" in c else f"{q[c]:.2f}" for c in columns]
                better = "yes" if q["kd_ref PSNR"] > q["kd PSNR"] else "**no**"
                lines.append(f"| {scene} | {r}: {title} | {variant} | " + " | ".join(cells) +
                             f" | {better} |")
    lines += ["", "## Gap to rendering a reconstructed as before (the paper's setting); goal: "
              "within 1 dB and 0.01 L1", "",
              "| scene | rendering | pipeline | kd_ref L1 - a | ks L1 - a | alpha L1 - a | "
              "kd_ref PSNR - a | rgb_ref PSNR - a |", "|---" * 8 + "|"]
    for scene in scenes:
        base = load(out, f"{scene}-a-before")
        if not (base and base.get("evaluation")):
            continue
        qa = quality(base)
        for variant in VARIANTS:
            for r in ["b", "c"]:
                rep = load(out, f"{scene}-{r}-{variant}")
                if not (rep and rep.get("evaluation")):
                    continue
                q = quality(rep)
                lines.append(
                    f"| {scene} | {r} | {variant} | {q['kd_ref L1'] - qa['kd_ref L1']:+.3f} | "
                    f"{q['ks L1'] - qa['ks L1']:+.3f} | {q['alpha L1'] - qa['alpha L1']:+.3f} | "
                    f"{q['kd_ref PSNR'] - qa['kd_ref PSNR']:+.2f} | "
                    f"{q['rgb_ref PSNR'] - qa['rgb_ref PSNR']:+.2f} |")
    for grid in ["2cm", "1cm"]:
        reports = {s: load(out, f"{s}-b-timing-{grid}") for s in PAPER_TOTALS[grid]}
        present = [s for s, r in reports.items() if r]
        if not present:
            continue
        lines += ["", f"## Per-stage ms per frame, {grid} observation voxels, shadows and "
                  "indirect light on (median; mean in brackets)", "",
                  "| stage | " + " | ".join(present) + " |", "|---" * (len(present) + 1) + "|"]
        for stage in STAGES:
            cells = []
            for s in present:
                t = reports[s].get("timings_ms", {}).get(stage)
                cells.append(f"{t['median']:.1f} ({t['mean']:.1f})" if t else "-")
            lines.append(f"| {stage} | " + " | ".join(cells) + " |")
        lines.append("| paper total (GTX 1080) | " +
                     " | ".join(str(PAPER_TOTALS[grid][s]) for s in present) + " |")
    print("\n".join(lines))


if __name__ == "__main__":
    main()
