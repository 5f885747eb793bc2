#!/usr/bin/env python3
"""Applies the pre-registered rule of models/README.md ("The noise gate") to the clean networks.

    select-noise-gate.py GLINT WORK MODELS_DIR

Pairs the shipped network of each BoundED model (MODELS_DIR/bounded-<c>c.json without its gate,
if it has one) with each clean network WORK/models/bounded-<c>c-clean-s<seed>.json at each
threshold of THRESHOLDS (`glint edges gate`), scores every pair and the shipped model on the CAD
validation sets WORK/cad-val (sharp) and WORK/cad-val-cut (boundary; 3-class only), never on
evaluation data, and copies the winning pair over MODELS_DIR/bounded-<c>c.json when the rule
says so. Writes WORK/noise-gate.json, and the pairs of every clean seed at the chosen threshold
as WORK/models/bounded-<c>c-gated-s<seed>.json.
"""
import json
import pathlib
import shutil
import sys

from bounded_eval import evaluate_groups, gate

THRESHOLDS = [0.01, 0.02, 0.03, 0.05, 0.07, 0.1, 0.15, 0.2, 0.3, 0.5]
MARGIN = 0.02      # the pair must beat the shipped model's validation score by this much
MAX_LOSS = 0.03    # and lose no more than this median MCC on any noisy validation group
NOISY = (0.5, 1.0)  # the noise levels (spacings) of those groups


def noisy_losses(candidate, shipped):
    """Median MCC lost against the shipped model on each noisy validation group."""
    return [shipped["groups"][g] - candidate["groups"][g]
            for g in shipped["groups"] if g[1] in NOISY]


def main():
    glint, work, models_dir = sys.argv[1], pathlib.Path(sys.argv[2]), pathlib.Path(sys.argv[3])
    trained, pairs = work / "models", work / "noise-gate"
    pairs.mkdir(exist_ok=True)
    decision = {"thresholds": THRESHOLDS, "margin": MARGIN, "max_noisy_loss": MAX_LOSS}
    threshold = None
    for classes in (3, 2):
        shipped = trained / f"bounded-{classes}c-shipped.json"
        if not shipped.exists():
            shutil.copyfile(models_dir / f"bounded-{classes}c.json", shipped)
        single = json.loads(shipped.read_text())
        single.pop("noise_gate", None)
        single.pop("sampling_gate", None)
        noisy = trained / f"bounded-{classes}c-noisy.json"
        noisy.write_text(json.dumps(single))
        clean = sorted(trained.glob(f"bounded-{classes}c-clean-s*.json"))
        # The threshold is chosen once, on the 3-class pairs; the 2-class pairs take it.
        thresholds = THRESHOLDS if threshold is None else [threshold]
        candidates = {}  # (low-noise seed, threshold) -> the pair's model file
        for network in clean:
            seed = network.stem.rsplit("-s", 1)[1]
            for t in thresholds:
                candidates[(seed, t)] = gate(glint, noisy, network, t,
                                             pairs / f"gated-{classes}c-s{seed}-t{t}.json")
        models = [shipped] + list(candidates.values())
        sharp = evaluate_groups(glint, work / "cad-val", "sharp", models,
                         pairs / f"val-sharp-{classes}c.json")
        boundary = (evaluate_groups(glint, work / "cad-val-cut", "boundary", models,
                             pairs / f"val-boundary-{classes}c.json") if classes == 3 else {})

        def score(stem):
            if classes == 2:
                return sharp[stem]["median"]
            return 0.5 * (sharp[stem]["median"] + boundary[stem]["median"])

        scores = {f"s{s}-t{t}": score(m.stem) for (s, t), m in candidates.items()}
        if threshold is None:  # rule 1: the threshold of clean seed 1, ties to the lower one
            threshold = max(THRESHOLDS, key=lambda t: (round(scores[f"s1-t{t}"], 6), -t))
        seeds = sorted({s for s, _ in candidates})
        best = max(seeds, key=lambda s: (scores[f"s{s}-t{threshold}"], -int(s)))  # rule 2
        winner = candidates[(best, threshold)]
        for seed in seeds:  # the pairs of every clean seed, for scripts/eval-bounded-cad.sh
            shutil.copyfile(candidates[(seed, threshold)],
                            trained / f"bounded-{classes}c-gated-s{seed}.json")
        losses = noisy_losses(sharp[winner.stem], sharp[shipped.stem])
        if classes == 3:
            losses += noisy_losses(boundary[winner.stem], boundary[shipped.stem])
        ships = (scores[f"s{best}-t{threshold}"] >= score(shipped.stem) + MARGIN
                 and max(losses) <= MAX_LOSS)  # rule 3
        if ships:
            shutil.copyfile(winner, models_dir / f"bounded-{classes}c.json")
        decision[f"{classes}c"] = {
            "scores": scores, "shipped_score": score(shipped.stem), "threshold": threshold,
            "clean_seed": int(best), "largest_noisy_loss": max(losses), "ships": ships,
            "groups": {"sharp": {stem: {f"{g[0]} noise {g[1]}": v for g, v in r["groups"].items()}
                                 for stem, r in sharp.items()
                                 if stem in (shipped.stem, winner.stem)}}}
        print(f"{classes}c: threshold {threshold}, clean seed {best}: score "
              f"{scores[f's{best}-t{threshold}']:.4f} vs shipped {score(shipped.stem):.4f}, "
              f"largest noisy loss {max(losses):.3f} -> "
              f"{'ship the pair' if ships else 'keep the shipped model'}")
    (work / "noise-gate.json").write_text(json.dumps(decision, indent=2))


if __name__ == "__main__":
    main()
