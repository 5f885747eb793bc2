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


def mcc_per_part(report, method):
    files = json.load(open(report))["files"]
    try:
        return np.array([f["scores"][method]["mcc"] for f in files])
    except KeyError:
        raise SystemExit(f"{report}: no method '{method}' in its files' scores")


def median_gain(report, shipped, candidate, parts):
    return (np.median(mcc_per_part(report, candidate)[parts])
            - np.median(mcc_per_part(report, shipped)[parts]))


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("shipped")
    parser.add_argument("candidate")
    parser.add_argument("sets", nargs="+", help="SHARP.json or SHARP.json:BOUNDARY.json")
    parser.add_argument("--draws", type=int, default=2000)
    parser.add_argument("--seed", type=int, default=0)
    args = parser.parse_args()
    reports = [s.split(":") for s in args.sets]
    sizes = [[len(json.load(open(r))["files"]) for r in pair] for pair in reports]

    def gain(draw):  # draw: one index array per report, or None for the observed parts
        per_set = []
        for pair, parts in zip(reports, draw):
            gains = [median_gain(r, args.shipped, args.candidate, p) for r, p in zip(pair, parts)]
            per_set.append(np.mean(gains))
        return float(np.mean(per_set))

    observed = gain([[slice(None)] * len(pair) for pair in reports])
    rng = np.random.default_rng(args.seed)
    draws = np.array([gain([[rng.integers(0, n, n) for n in set_sizes] for set_sizes in sizes])
                      for _ in range(args.draws)])
    low, high = np.percentile(draws, [5, 95])
    print(f"{args.candidate} - {args.shipped}: observed gain {observed:+.4f}; {args.draws} "
          f"draws: median {np.median(draws):+.4f}, sd {draws.std():.4f}, "
          f"5-95 % [{low:+.4f}, {high:+.4f}]")


if __name__ == "__main__":
    main()
