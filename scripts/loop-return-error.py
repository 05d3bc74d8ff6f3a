#!/usr/bin/env python3
"""How far a loop's return pass is off its first pass: compares the motion from the first to the
last pose of an estimated trajectory with the ground truth's (TUM files, poses matched by
timestamp within 10 ms). For a sequence that ends where it began, this is the error the loop
closure has to remove; no alignment is involved. Prints "return error: X m, Y deg". Pure Python.

  scripts/loop-return-error.py ESTIMATE.txt GROUNDTRUTH.txt
"""
import math
import sys


def read(path):
    poses = []
    with open(path) as f:
        for line in f:
            v = line.split()
            if len(v) == 8 and not line.startswith("#"):
                poses.append([float(x) for x in v])
    return poses


def conj(q):
    return (-q[0], -q[1], -q[2], q[3])


def mul(a, b):
    ax, ay, az, aw = a
    bx, by, bz, bw = b
    return (aw * bx + ax * bw + ay * bz - az * by, aw * by - ax * bz + ay * bw + az * bx,
            aw * bz + ax * by - ay * bx + az * bw, aw * bw - ax * bx - ay * by - az * bz)


def rotate(q, v):
    x, y, z, _ = mul(mul(q, (v[0], v[1], v[2], 0.0)), conj(q))
    return (x, y, z)


def relative(first, last):
    """The last pose in the first's frame: (translation, quaternion)."""
    q0, q1 = tuple(first[4:8]), tuple(last[4:8])
    d = [last[i] - first[i] for i in (1, 2, 3)]
    return rotate(conj(q0), d), mul(conj(q0), q1)


def nearest(poses, t):
    best = min(poses, key=lambda p: abs(p[0] - t))
    return best if abs(best[0] - t) < 0.01 else None


def main():
    if len(sys.argv) != 3:
        sys.exit(__doc__)
    est, gt = read(sys.argv[1]), read(sys.argv[2])
    if len(est) < 2:
        sys.exit("loop-return-error: fewer than two poses in " + sys.argv[1])
    g0, g1 = nearest(gt, est[0][0]), nearest(gt, est[-1][0])
    if g0 is None or g1 is None:
        sys.exit("loop-return-error: no ground truth at the first or last estimated pose")
    te, qe = relative(est[0], est[-1])
    tg, qg = relative(g0, g1)
    dq = mul(conj(qg), qe)
    angle = 2 * math.degrees(math.acos(min(1.0, abs(dq[3]))))
    print("return error: %.3f m, %.2f deg" % (math.dist(te, tg), angle))


if __name__ == "__main__":
    main()
