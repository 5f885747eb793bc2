"""`glint edges eval` of several BoundED models on one folder, for the selection scripts."""
import json
import pathlib
import statistics
import subprocess


def run_eval(glint, folder, task, models, report):
    """The eval report of `models` on `folder` (run once; an existing report is reused)."""
    if not report.exists():
        subprocess.run(["nice", "-n", "10", glint, "--quiet", "edges", "eval", str(folder),
                        "--task", task, "--no-baseline", "--report", str(report)]
                       + [a for m in models for a in ("--model", str(m))],
                       check=True, stdout=subprocess.DEVNULL)
    return json.loads(report.read_text())


def evaluate_groups(glint, folder, task, models, report):
    """Per model: median MCC over the folder, and per (sampling, noise) group of its manifest."""
    files = run_eval(glint, folder, task, models, report)["files"]
    manifest = json.loads((folder / "manifest.json").read_text())
    group_of = {c["file"]: (c["sampling"], float(c["noise_spacings"])) for c in manifest["clouds"]}
    result = {}
    for model in models:
        method = "glint:" + model.stem
        mcc = [(group_of[pathlib.Path(f["file"]).name], f["scores"][method]["mcc"]) for f in files]
        groups = {}
        for group, value in mcc:
            groups.setdefault(group, []).append(value)
        result[model.stem] = {"median": statistics.median(v for _, v in mcc),
                              "groups": {g: statistics.median(v) for g, v in groups.items()}}
    return result


def gate(glint, model, gate_model, threshold, output, statistic="noise"):
    """`glint edges gate` (run once; an existing output is reused)."""
    if not output.exists():
        subprocess.run([glint, "--quiet", "edges", "gate", str(model), str(gate_model),
                        "--statistic", statistic, "--threshold", str(threshold), "-o",
                        str(output)], check=True, stdout=subprocess.DEVNULL)
    return output
