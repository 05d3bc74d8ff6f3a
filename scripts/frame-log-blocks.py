#!/usr/bin/env python3
"""How cost and the map grow along a run: reads frame logs (--frame-log of slamdunk-rawlog or
slamdunk-live) of one sequence, one per run, and prints for each block of BLOCK frames the
tracking time (p50, p95 and max per frame), the largest feature pool the frames were matched
against, the keyframes made in the block and the keyframe count at its end. With several runs,
each figure is the median of the runs'. Pure Python (no numpy).

  scripts/frame-log-blocks.py BLOCK FRAMES.csv [FRAMES.csv ...]
"""
import csv
import statistics
import sys


def percentile(values, p):
    """Linear between the two nearest ranks, as the apps' summaries compute it."""
    ordered = sorted(values)
    rank = p / 100 * (len(ordered) - 1)
    lo = int(rank)
    hi = min(lo + 1, len(ordered) - 1)
    return ordered[lo] + (rank - lo) * (ordered[hi] - ordered[lo])


def blocks(path, size):
    with open(path, newline="") as f:
        rows = list(csv.DictReader(f))
    out = []
    for start in range(0, len(rows), size):
        block = rows[start:start + size]
        ms = [float(r["ms_total"]) for r in block if r["ms_total"]]
        pool = [int(r["pool_size"]) for r in block if r["pool_size"]]
        out.append({
            "first": start,
            "last": start + len(block) - 1,
            "p50": statistics.median(ms) if ms else float("nan"),
            "p95": percentile(ms, 95) if ms else float("nan"),
            "max": max(ms) if ms else float("nan"),
            "pool": max(pool) if pool else 0,
            "new": sum(1 for r in block if r["new_keyframe"] in ("1", "true")),
            "keyframes": int(block[-1]["keyframes"]) if block[-1]["keyframes"] else 0,
        })
    return out


def main():
    if len(sys.argv) < 3:
        sys.exit(__doc__)
    size = int(sys.argv[1])
    runs = [blocks(p, size) for p in sys.argv[2:]]
    print("| frames | tracking ms p50 / p95 / max | pool features (max) | new keyframes | keyframes |")
    print("|---|---|---|---|---|")
    for i, block in enumerate(runs[0]):
        m = lambda key: statistics.median(run[i][key] for run in runs if i < len(run))
        print(f"| {block['first']}-{block['last']} | {m('p50'):.1f} / {m('p95'):.1f} / "
              f"{m('max'):.1f} | {m('pool'):,.0f} | {m('new'):.0f} | {m('keyframes'):.0f} |")


if __name__ == "__main__":
    main()
