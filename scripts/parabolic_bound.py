#!/usr/bin/python3
"""Von Neumann check of the level set's parabolic time-step bound (sparse_field.cpp, time_step).

Linearises the difference-of-normals curvature (speed.cpp) about a front phi = n.x with |grad phi| = 1
and scans the symbol S(xi, n) over frequencies xi in [-pi, pi]^3 and unit normals n. Forward Euler
is stable while |1 + dt*w*S| <= 1, i.e. w*dt <= 2 / max|S|. Prints max|S| (8: the checkerboard along
the front) and the bound (1/4). Needs numpy (/usr/bin/python3 on Debian: python3-numpy).

Usage: scripts/parabolic_bound.py [--freq 33] [--normals 400]
"""
import argparse
import sys

import numpy as np


def symbol(xi, n):
    """S for frequencies xi (..., 3) and one unit normal n (3,)."""
    total = np.zeros(xi.shape[:-1], complex)
    for a in range(3):
        ea = np.exp(1j * xi[..., a])
        g = []
        for c in range(3):
            if c == a:
                g.append(ea - 1.0)  # phi(p + e_a) - phi(p) at the half point
            else:  # the averaged central difference across, at the half point
                g.append(0.25 * (1.0 + ea) * 2j * np.sin(xi[..., c]))
        ng = n[0] * g[0] + n[1] * g[1] + n[2] * g[2]
        half = g[a] - n[a] * ng  # linearised unit-normal component
        total += (1.0 - np.exp(-1j * xi[..., a])) * half
    return total


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--freq", type=int, default=33, help="frequencies per axis (odd: includes 0 and +-pi)")
    ap.add_argument("--normals", type=int, default=400, help="random unit normals besides the axes and diagonals")
    args = ap.parse_args()
    if args.freq < 3 or args.normals < 0:
        sys.exit("parabolic_bound: --freq must be >= 3 and --normals >= 0")
    t = np.linspace(-np.pi, np.pi, args.freq)
    xi = np.stack(np.meshgrid(t, t, t, indexing="ij"), axis=-1)
    normals = [np.array(v, float) for v in ([0, 0, 1], [1, 1, 0], [1, 1, 1], [1, 2, 3])]
    normals += list(np.random.default_rng(1).normal(size=(args.normals, 3)))
    worst, where = 0.0, None
    for n in normals:
        n = n / np.linalg.norm(n)
        s = symbol(xi, n)
        if np.max(np.abs(s.imag)) > 1e-9 or np.max(s.real) > 1e-9:
            sys.exit("parabolic_bound: the symbol is not real and non-positive; the scheme is not a diffusion")
        k = int(np.argmax(np.abs(s)))
        if abs(s.flat[k]) > worst:
            worst, where = abs(s.flat[k]), (n, xi.reshape(-1, 3)[k])
    print(f"max |S| = {worst:.6f} at n = {np.round(where[0], 3)}, xi = {np.round(where[1], 3)}")
    print(f"stable for w*dt <= 2 / max|S| = {2.0 / worst:.6f}")


if __name__ == "__main__":
    main()
