#!/usr/bin/python3
"""Von Neumann check of the level set's parabolic time-step bound (sparse_field.cpp, time_step).

Linearises the difference-of-normals curvature (speed.cpp) about a front phi = n.u with |grad phi| = 1
in index units u and scans the symbol S(xi, n) over frequencies xi in [-pi, pi]^3 and unit normals n.
The curvature is the physical one (differences divided by the voxel sizes h, --spacing) and multiplies
|grad phi| per finest voxel (the physical norm times h_min), as in a step. Forward Euler is stable
while |1 + dt*w*S| <= 1, i.e. w*dt <= 2 / max|S|. Prints max|S| (8 at 1 mm: the checkerboard along
the front), the bound (1/4 at 1 mm) and max|S| over 8 / h_min, the factor time_step applies (at most
1 for a safe bound).
Needs numpy (/usr/bin/python3 on Debian: python3-numpy).

Usage: scripts/parabolic_bound.py [--freq 33] [--normals 400] [--spacing 1,1,1]
"""
import argparse
import sys

import numpy as np


def symbol(xi, n, h=(1.0, 1.0, 1.0)):
    """S for frequencies xi (..., 3), one unit normal n (3,) in index units and voxel sizes h."""
    h = np.asarray(h, float)
    big_g = n / h  # the physical gradient of phi = n.u
    big_n = big_g / np.linalg.norm(big_g)
    total = np.zeros(xi.shape[:-1], complex)
    for a in range(3):
        ea = np.exp(1j * xi[..., a])
        g = []
        for c in range(3):
            if c == a:
                g.append(ea - 1.0)  # phi(p + e_a) - phi(p) at the half point
            else:  # the averaged central difference across, at the half point
                g.append(0.25 * (1.0 + ea) * 2j * np.sin(xi[..., c]))
        g = [g[c] / h[c] for c in range(3)]  # per millimetre
        ng = big_n[0] * g[0] + big_n[1] * g[1] + big_n[2] * g[2]
        half = (g[a] - big_n[a] * ng) / np.linalg.norm(big_g)  # linearised unit-normal component
        total += (1.0 - np.exp(-1j * xi[..., a])) * half / h[a]
    # The curvature multiplies |grad phi| per finest voxel: the physical norm |G| times h_min.
    return total * np.linalg.norm(big_g) * min(h)


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--freq", type=int, default=33, help="frequencies per axis (odd: includes 0 and +-pi)")
    ap.add_argument("--normals", type=int, default=400, help="random unit normals besides the axes and diagonals")
    ap.add_argument("--spacing", default="1,1,1", help="voxel sizes hx,hy,hz (mm)")
    args = ap.parse_args()
    try:
        h = [float(v) for v in args.spacing.split(",")]
    except ValueError:
        h = []
    if len(h) != 3 or not all(np.isfinite(v) and v > 0 for v in h):
        sys.exit("parabolic_bound: --spacing must be three positive numbers hx,hy,hz")
    if args.freq < 3 or args.normals < 0:
        sys.exit("parabolic_bound: --freq must be >= 3 and --normals >= 0")
    t = np.linspace(-np.pi, np.pi, args.freq)
    xi = np.stack(np.meshgrid(t, t, t, indexing="ij"), axis=-1)
    normals = [np.array(v, float) for v in ([0, 0, 1], [1, 1, 0], [1, 1, 1], [1, 2, 3])]
    normals += list(np.random.default_rng(1).normal(size=(args.normals, 3)))
    worst, where = 0.0, None
    for n in normals:
        n = n / np.linalg.norm(n)
        s = symbol(xi, n, h)
        if np.max(np.abs(s.imag)) > 1e-9 or np.max(s.real) > 1e-9:
            sys.exit("parabolic_bound: the symbol is not real and non-positive; the scheme is not a diffusion")
        k = int(np.argmax(np.abs(s)))
        if abs(s.flat[k]) > worst:
            worst, where = abs(s.flat[k]), (n, xi.reshape(-1, 3)[k])
    print(f"max |S| = {worst:.6f} at n = {np.round(where[0], 3)}, xi = {np.round(where[1], 3)}")
    print(f"stable for w*dt <= 2 / max|S| = {2.0 / worst:.6f}")
    factor = 1.0 / min(h)
    print(f"max|S| / (8 / h_min) = {worst / (8.0 * factor):.6f} (time_step's bound is safe if <= 1)")


if __name__ == "__main__":
    main()
