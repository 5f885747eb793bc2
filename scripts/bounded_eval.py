"""`glint edges eval` of several BoundED models on one folder, for the selection scripts."""
import json
import subprocess


def run_eval(glint, folder, task, models, report):
    """The eval report of `models` on `folder` (run once; an existing report is reused)."""
    if not report.exists():
        subprocess.run(["nice", "-n", "10", glint, "--quiet", "edges", "eval", str(folder),
                        "--task", task, "--no-baseline", "--report", str(report)]
                       + [a for m in models for a in ("--model", str(m))],
                       check=True, stdout=subprocess.DEVNULL)
    return json.loads(report.read_text())
