#!/usr/bin/env python3
"""Applies the pre-registered rules of models/README.md ("The low-noise mesh-vertex network").

    select-clean-vertex-gate.py GLINT WORK MODELS_DIR DATA

The candidate: the 3-class model's sampling gate as shipped, its mesh-vertex network given a
noise gate (threshold 0.01, the noise gate's validated threshold) whose low-noise network is an
area-weighted mesh-vertex network, WORK/models/bounded-3c-mesh-vertex-area-s<seed>.json.
Clean-vertex score: the mean of the median sharp MCC of the clean mesh-vertex parts of a closed
set and the median boundary MCC of those of its cut-open twin.
1. First test, WORK/cad-dec2 and WORK/cad-dec2-cut (seed 5501, 180 parts, every sampling): the
   best seed ships if its clean-vertex score is 0.03 above the shipped model's and no
   sampling x noise group loses more than 0.02.
2. Second test, written after the first had failed on its clean boundary group (24 clean
   mesh-vertex parts per set): the first test's best seed on WORK/cad-dec3 and WORK/cad-dec3-cut
   (seed 5601, 160 mesh-vertex parts, noise 0 or 0.25): it ships if its clean-vertex score is
   0.03 above, neither clean group loses more than 0.01 and no noise-0.25 group more than 0.02.
Either way only if default-eval's median sharp MCC stays above the thesis's 0.423. The rule's
speed conditions (1M points at 500k points/s; a clean mesh-vertex cloud at most 1.15x the pair's
time) are measured apart (docs/benchmarks.md): the chain met the first and failed the second, so
it never replaces MODELS_DIR/bounded-3c.json; a chain that passes the tests above is written as
the opt-in MODELS_DIR/bounded-3c-cad-vertices.json.
Writes WORK/clean-vertex-gate.json and the chains as WORK/models/bounded-3c-chain-s<seed>.json.
"""
import json
import pathlib
import shutil
import statistics
import sys

from bounded_eval import evaluate_groups, gate, run_eval

MARGIN = 0.03
MAX_LOSS = 0.02
MAX_CLEAN_LOSS = 0.01
NOISE_THRESHOLD = 0.01
THESIS_DEFAULT_EVAL = 0.423
NETWORK_KEYS = ("input_mean", "input_std", "layers", "parameter_count", "training",
                "neighbour_weights", "noise_gate", "sampling_gate")


def split_shipped(shipped, folder):
    """The shipped pair's general network, its mesh-vertex network (each as a model file of its
    own) and its sampling threshold."""
    root = json.loads(shipped.read_text())
    gate_entry = root["sampling_gate"]
    mesh_vertex = {k: v for k, v in root.items() if k not in NETWORK_KEYS}
    mesh_vertex.update({k: v for k, v in gate_entry["mesh_vertices"].items() if k != "noise_gate"})
    general = {k: v for k, v in root.items() if k != "sampling_gate"}
    paths = folder / "bounded-3c-general.json", folder / "bounded-3c-mesh-vertex-shipped.json"
    for path, model in zip(paths, (general, mesh_vertex)):
        path.write_text(json.dumps(model))
    return paths[0], paths[1], gate_entry["threshold"]


def clean_vertex_score(groups, stem):
    return statistics.mean(g[stem]["groups"][("vertices", 0.0)] for g in groups)


def main():
    glint, work, models_dir = sys.argv[1], pathlib.Path(sys.argv[2]), pathlib.Path(sys.argv[3])
    data = pathlib.Path(sys.argv[4])
    trained, reports = work / "models", work / "clean-vertex-gate"
    reports.mkdir(exist_ok=True)
    general, mesh_vertex, threshold = split_shipped(models_dir / "bounded-3c.json", trained)
    shipped = gate(glint, general, mesh_vertex, threshold, trained / "bounded-3c-pair.json",
                   statistic="sampling")
    chains = {}
    for network in sorted(trained.glob("bounded-3c-mesh-vertex-area-s*.json")):
        seed = network.stem.rsplit("-s", 1)[1]
        clean_gated = gate(glint, mesh_vertex, network, NOISE_THRESHOLD,
                           trained / f"bounded-3c-mesh-vertex-clean-gated-s{seed}.json")
        chains[seed] = gate(glint, general, clean_gated, threshold,
                            trained / f"bounded-3c-chain-s{seed}.json", statistic="sampling")
    models = [shipped] + list(chains.values())

    def groups_on(name, models):
        return [evaluate_groups(glint, work / name, "sharp", models, reports / f"{name}-sharp.json"),
                evaluate_groups(glint, work / f"{name}-cut", "boundary", models,
                                reports / f"{name}-boundary.json")]

    first = groups_on("cad-dec2", models)
    scores = {seed: clean_vertex_score(first, m.stem) for seed, m in chains.items()}
    base = clean_vertex_score(first, shipped.stem)
    best = max(scores, key=lambda s: (round(scores[s], 6), -int(s)))  # ties: lower seed
    winner = chains[best]
    first_loss = max(g[shipped.stem]["groups"][k] - g[winner.stem]["groups"][k]
                     for g in first for k in g[shipped.stem]["groups"])
    decision = {"seed": int(best), "first_test": {
        "clean_vertex_scores": scores, "shipped": base, "largest_group_loss": first_loss,
        "passed": scores[best] >= base + MARGIN and first_loss <= MAX_LOSS}}
    ships = decision["first_test"]["passed"]
    if not ships:
        second = groups_on("cad-dec3", [shipped, winner])
        gain = clean_vertex_score(second, winner.stem) - clean_vertex_score(second, shipped.stem)
        losses = [(k, g[shipped.stem]["groups"][k] - g[winner.stem]["groups"][k])
                  for g in second for k in g[shipped.stem]["groups"]]
        ships = gain >= MARGIN and all(
            loss <= (MAX_CLEAN_LOSS if k == ("vertices", 0.0) else MAX_LOSS) for k, loss in losses)
        decision["second_test"] = {"clean_vertex_gain": gain,
                                   "group_losses": [[*k, loss] for k, loss in losses],
                                   "passed": ships}
    if ships:  # the veto: default-eval stays above the thesis
        report = run_eval(glint, data / "pointclouds/default-eval", "sharp", [winner],
                          reports / "default-eval.json")
        default_eval = statistics.median(f["scores"]["glint:" + winner.stem]["mcc"]
                                         for f in report["files"])
        decision["default_eval"] = default_eval
        ships = default_eval > THESIS_DEFAULT_EVAL
    decision["passes_quality"] = ships
    if ships:
        shutil.copyfile(winner, models_dir / "bounded-3c-cad-vertices.json")
    print(f"low-noise area-weighted seed {best}: "
          f"{'the chain passes the quality tests' if ships else 'the chain fails'}")
    (work / "clean-vertex-gate.json").write_text(json.dumps(decision, indent=2))


if __name__ == "__main__":
    main()
