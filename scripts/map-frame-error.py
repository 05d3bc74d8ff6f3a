#!/usr/bin/env python3
"""How far a map's keyframes are from the ground truth expressed in the map's own frame (the
frame of the first ground-truth file's first pose: where the first session started), with no
alignment: what a second session joined to a loaded map must get right. Ground truth from
several TUM files (the sessions of one walk), matched by timestamp within 10 ms. Prints
"keyframes: N, worst X m, Y deg, median Z m". Pure Python.

  scripts/map-frame-error.py KEYFRAMES.txt FIRST_SESSION_GT.txt [MORE_GT.txt ...]
"""
import importlib.util
import math
import os
import statistics
import sys

_spec = importlib.util.spec_from_file_location(
    "loop_return_error", os.path.join(os.path.dirname(__file__), "loop-return-error.py"))
tum = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(tum)


def main():
    if len(sys.argv) < 3:
        sys.exit(__doc__)
    keyframes = tum.read(sys.argv[1])
    first = tum.read(sys.argv[2])
    truth = [p for path in sys.argv[2:] for p in tum.read(path)]
    if not keyframes or not first:
        sys.exit("map-frame-error: no poses in " + (sys.argv[1] if not keyframes else sys.argv[2]))
    errors, angles = [], []
    for k in keyframes:
        g = tum.nearest(truth, k[0])
        if g is None:
            sys.exit("map-frame-error: no ground truth at keyframe %.6f" % k[0])
        tg, qg = tum.relative(first[0], g)  # the truth in the first session's frame
        dq = tum.mul(tum.conj(qg), tuple(k[4:8]))
        errors.append(math.dist(tg, k[1:4]))
        angles.append(2 * math.degrees(math.acos(min(1.0, abs(dq[3])))))
    print("keyframes: %d, worst %.4f m, %.2f deg, median %.4f m" %
          (len(keyframes), max(errors), max(angles), statistics.median(errors)))


if __name__ == "__main__":
    main()
