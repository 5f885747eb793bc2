#!/usr/bin/env python3
"""Applies the pre-registered selection rule of models/README.md ("Which model ships").

    select-bounded.py GLINT WORK MODELS_DIR

Scores the three training seeds of each BoundED model and the model shipped before them on the
CAD validation sets WORK/cad-val (sharp) and WORK/cad-val-cut (boundary; 3-class only), never on
evaluation data, then copies the winner over MODELS_DIR/bounded-<c>c.json when the rule says so.
Writes WORK/selection.json.
"""
import json
import pathlib
import shutil
import sys

from bounded_eval import run_eval

MARGIN = 0.02  # the new model must beat the old one's validation score by this much
TIE = 0.005    # seeds closer than this are split by the training validation split's edge F1


def median_mcc(glint, folder, task, models, report):
    summary = run_eval(glint, folder, task, models, report)["summary"]
    return {name.removeprefix("glint:"): s["median"]["mcc"] for name, s in summary.items()}


def main():
    glint, work, models_dir = sys.argv[1], pathlib.Path(sys.argv[2]), pathlib.Path(sys.argv[3])
    trained = work / "models"
    decision = {"margin": MARGIN, "tie": TIE}
    for classes in (3, 2):
        old = trained / f"bounded-{classes}c-old.json"
        if not old.exists():
            shutil.copyfile(models_dir / f"bounded-{classes}c.json", old)
        seeds = sorted(trained.glob(f"bounded-{classes}c-s*.json"))
        candidates = [old] + seeds
        sharp = median_mcc(glint, work / "cad-val", "sharp", candidates,
                           work / f"val-sharp-{classes}c.json")
        boundary = (median_mcc(glint, work / "cad-val-cut", "boundary", candidates,
                               work / f"val-boundary-{classes}c.json") if classes == 3 else {})
        scores = {}
        for model in candidates:
            name = model.stem
            value = sharp[name] if classes == 2 else 0.5 * (sharp[name] + boundary[name])
            f1 = json.loads(model.read_text())["training"].get("threshold_tuning", {}).get(
                "validation_edge_f1", 0.0)
            scores[name] = {"score": value, "sharp_mcc": sharp[name],
                            "boundary_mcc": boundary.get(name), "validation_edge_f1": f1}
        new = [m.stem for m in seeds]
        top = max(scores[n]["score"] for n in new)
        close = [n for n in new if top - scores[n]["score"] < TIE]
        best = max(close, key=lambda n: (scores[n]["validation_edge_f1"], -new.index(n)))
        ships = scores[best]["score"] >= scores[old.stem]["score"] + MARGIN
        if ships:
            shutil.copyfile(trained / f"{best}.json", models_dir / f"bounded-{classes}c.json")
        decision[f"{classes}c"] = {"scores": scores, "best_seed": best, "replaces_old": ships}
        print(f"{classes}c: best {best} score {scores[best]['score']:.4f}, old "
              f"{scores[old.stem]['score']:.4f} -> {'ship ' + best if ships else 'keep the old model'}")
    (work / "selection.json").write_text(json.dumps(decision, indent=2))


if __name__ == "__main__":
    main()
