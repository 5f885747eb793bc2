#!/usr/bin/env python3
"""Markdown tables of scripts/eval-bounded-cad.sh's reports: median MCC per method, the seeds of
each recipe (bounded-3c-s1..3, bounded-3c-gated-s1..3) as their median and range.

    bounded-cad-summary.py WORK
"""
import json
import pathlib
import re
import statistics
import sys


def row(report):
    summary = json.loads(report.read_text())["summary"]
    seeds, cells = {}, {}
    for name, s in summary.items():
        mcc = s["median"]["mcc"]
        name = name.removeprefix("glint:")
        if seed := re.search(r"-s\d+$", name):  # the seeds of one recipe share a column
            seeds.setdefault(name[:seed.start()], []).append(mcc)
        else:
            cells[name] = f"{mcc:.3f}"
    for recipe, values in seeds.items():
        cells[f"{recipe} ({len(values)} seeds)"] = (
            f"{statistics.median(values):.3f} ({min(values):.3f}-{max(values):.3f})")
    return cells


def wide_angle_gap(report):
    """The angle-gap MCC at 4 spacings, k 64, from the sibling report of a boundary set."""
    if "-boundary-3c" not in report.name:
        return {}
    wide = report.with_name(report.name.replace("-boundary-3c", "-boundary-angle-gap-4"))
    if not wide.exists():
        return {}
    mcc = json.loads(wide.read_text())["summary"]["angle-gap"]["median"]["mcc"]
    return {"angle-gap 4 spacings, k 64": f"{mcc:.3f}"}


def table(title, reports):
    rows = [(r.stem, row(r) | wide_angle_gap(r)) for r in reports]
    if not rows:
        return
    columns = []
    for _, cells in rows:
        columns += [c for c in cells if c not in columns]
    print(f"\n### {title}\n")
    print("| set | " + " | ".join(columns) + " |")
    print("|---" * (len(columns) + 1) + "|")
    for name, cells in rows:
        print(f"| {name} | " + " | ".join(cells.get(c, "–") for c in columns) + " |")


def main():
    work = pathlib.Path(sys.argv[1])
    for classes in ("3c", "2c"):
        table(f"sharp edges, median MCC ({classes})", sorted(work.glob(f"cad-*-sharp-{classes}.json")))
    table("boundary, parts cut open by a plane, median MCC (3c)",
          sorted(work.glob("cad-*-boundary-3c.json")))
    table("default-eval and shrec19, sharp, median MCC",
          sorted(work.glob("default-eval-*.json")) + sorted(work.glob("shrec19-*.json")))


if __name__ == "__main__":
    main()
