#!/usr/bin/env python3
"""What the keyframe policy saw: reads a frame log (--frame-log of slamdunk-rawlog or
slamdunk-live) and, when given, the ground truth, and prints how often keyframes were spawned,
the overlap and counted grid cells at the spawning frames, and how far the camera had turned and
moved since the previous keyframe. Pure Python (no numpy).

  scripts/keyframe-policy-report.py FRAMES.csv [GROUNDTRUTH.txt]
"""
import csv
import math
import sys


def quat_angle_deg(q1, q2):
    d = abs(sum(a * b for a, b in zip(q1, q2)))
    return math.degrees(2 * math.acos(min(1.0, d)))


def nearest(gt, t):
    lo, hi = 0, len(gt) - 1
    while lo < hi:
        mid = (lo + hi) // 2
        if gt[mid][0] < t:
            lo = mid + 1
        else:
            hi = mid
    best = min((i for i in (lo - 1, lo) if 0 <= i < len(gt)), key=lambda i: abs(gt[i][0] - t))
    return gt[best]


def median(v):
    v = sorted(v)
    return v[len(v) // 2] if v else float("nan")


def main():
    if len(sys.argv) < 2:
        sys.exit(__doc__)
    rows = list(csv.DictReader(open(sys.argv[1])))
    gt = []
    if len(sys.argv) > 2:
        for line in open(sys.argv[2]):
            if line.startswith("#") or not line.strip():
                continue
            f = [float(x) for x in line.split()[:8]]
            gt.append((f[0], f[1:4], f[4:8]))
        gt.sort()
    tracked = [r for r in rows if r["status"] == "tracked"]
    spawns = [r for r in rows if r["new_keyframe"] == "1"]
    print(f"frames {len(rows)}, keyframes {len(spawns)}: one every "
          f"{len(rows) / max(1, len(spawns)):.1f} frames")
    gaps = [int(b["index"]) - int(a["index"]) for a, b in zip(spawns, spawns[1:])]
    print(f"frames between keyframes: median {median(gaps)}, min {min(gaps, default=0)}, "
          f"max {max(gaps, default=0)}")
    at = [r for r in spawns if r["status"] == "tracked"]
    print(f"at a spawn: overlap median {median([float(r['overlap']) for r in at]):.2f}, "
          f"cells counted median {median([int(r.get('overlap_cells', 0)) for r in at])} of 16, "
          f"inliers median {median([int(r['inliers']) for r in at])} "
          f"(all tracked frames: {median([int(r['inliers']) for r in tracked])}), "
          f"features median {median([int(r['features']) for r in at])} "
          f"(all: {median([int(r['features']) for r in tracked])})")
    few = sum(1 for r in at if int(r.get("overlap_cells", 16)) <= 8)
    print(f"spawns with at most 8 cells counted (little texture or blur): {few} of {len(at)}")
    if gt:
        turned, moved, speed = [], [], []
        for a, b in zip(spawns, spawns[1:]):
            ga, gb = nearest(gt, float(a["timestamp"])), nearest(gt, float(b["timestamp"]))
            turned.append(quat_angle_deg(ga[2], gb[2]))
            moved.append(math.dist(ga[1], gb[1]))
            dt = float(b["timestamp"]) - float(a["timestamp"])
            speed.append(turned[-1] / dt if dt > 0 else 0)
        print(f"between consecutive keyframes the camera turned median {median(turned):.1f} deg "
              f"(max {max(turned, default=0):.1f}) and moved median {median(moved):.3f} m; "
              f"mean turn rate there median {median(speed):.0f} deg/s")


if __name__ == "__main__":
    main()
