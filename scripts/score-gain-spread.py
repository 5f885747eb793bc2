#!/usr/bin/env python3
"""How widely a candidate's validation-score gain over the shipped model spreads when the
validation parts are resampled: the figure a selection rule's margin should be set against.

    score-gain-spread.py SHIPPED CANDIDATE SET [SET ...] [--draws 2000] [--seed 0]

SHIPPED and CANDIDATE are method names of `glint edges eval` reports ("glint:bounded-2c").
Each SET is one validation seed's reports: SHARP.json for a 2-class score, or
SHARP.json:BOUNDARY.json for a 3-class score (the mean of the two medians, rule 2 of
models/README.md). The score is the mean over the sets, as the area-weights and later rules
take it. Parts are drawn with replacement within each report, the shipped model and the
candidate on the same draw; prints the observed gain and the draws' median, standard deviation
and 5-95 % range.
"""
import argparse
import json

import numpy as np


def mcc_per_part(report, methods):
    """Per method, its MCC on every part of the report, in the report's order."""
    files = json.load(open(report))["files"]
    try:
        return [np.array([f["scores"][m]["mcc"] for f in files]) for m in methods]
    except KeyError as missing:
        raise SystemExit(f"{report}: no method {missing} in its files' scores")


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("shipped")
    parser.add_argument("candidate")
    parser.add_argument("sets", nargs="+", help="SHARP.json or SHARP.json:BOUNDARY.json")
    parser.add_argument("--draws", type=int, default=2000)
    parser.add_argument("--seed", type=int, default=0)
    args = parser.parse_args()
    # Per set, per report: (shipped, candidate) MCC per part.
    sets = [[mcc_per_part(r, (args.shipped, args.candidate)) for r in s.split(":")]
            for s in args.sets]

    def gain(draw):  # draw: one index array (or slice) per report of every set
        return float(np.mean([np.mean([np.median(candidate[parts]) - np.median(shipped[parts])
                                       for (shipped, candidate), parts in zip(reports, chosen)])
                              for reports, chosen in zip(sets, draw)]))

    observed = gain([[slice(None)] * len(reports) for reports in sets])
    rng = np.random.default_rng(args.seed)
    draws = np.array([gain([[rng.integers(0, len(shipped), len(shipped)) for shipped, _ in reports]
                            for reports in sets])
                      for _ in range(args.draws)])
    low, high = np.percentile(draws, [5, 95])
    print(f"{args.candidate} - {args.shipped}: observed gain {observed:+.4f}; {args.draws} "
          f"draws: median {np.median(draws):+.4f}, sd {draws.std():.4f}, "
          f"5-95 % [{low:+.4f}, {high:+.4f}]")


if __name__ == "__main__":
    main()
