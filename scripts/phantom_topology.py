#!/usr/bin/python3
"""Judges the topology of a `liveset demo` (phantom) folder against its truth, independently of liveset
(nibabel + numpy + scipy): the Betti numbers of seg_repaired.nii.gz (b0 pieces, 26-connected; b2 enclosed
6-connected background regions; b1 = b0 + b2 - chi, chi counted on the closed voxel cubes), whether the
white-matter core (the truth shell's enclosed region, the largest enclosed region of the outside of
truth_gm.nii.gz) lies in a cavity of the mask ("sealed": the region of the mask's outside holding most
of its unsegmented voxels is enclosed) or is joined to the outside ("open"), and the other cavities
("bubbles": spurious ones, or white matter the mask walled off). `holes` (Euler characteristic vs truth) can read 0 with the core open and a
bubble balancing it; this cannot. Prints one line: b0 b1 b2 core sealed|open bubbles N.
Usage: scripts/phantom_topology.py DIR [SEG=seg_repaired.nii.gz]"""
import itertools, sys
import nibabel as nib
import numpy as np
from scipy import ndimage as ndi


def euler26(m):
    """chi = V - E + F - C of the union of the closed unit cubes of the foreground voxels."""
    m = np.pad(m.astype(bool), 1)
    def cells(shifts):  # cells of the dual grid touched by a foreground voxel among the shifts
        out = np.zeros(tuple(s + 1 for s in m.shape), bool)
        for s in shifts:
            out[tuple(slice(a, a + n) for a, n in zip(s, m.shape))] |= m
        return int(out.sum())
    corners = list(itertools.product((0, 1), repeat=3))
    v = cells(corners)
    e = sum(cells([s for s in corners if s[ax] == 0]) for ax in range(3))
    f = sum(cells([tuple(b if i == ax else 0 for i in range(3)) for b in (0, 1)]) for ax in range(3))
    return v - e + f - int(m.sum())


def main():
    if len(sys.argv) < 2:
        sys.exit(__doc__)
    d = sys.argv[1]
    seg = sys.argv[2] if len(sys.argv) > 2 else 'seg_repaired.nii.gz'
    truth = np.asarray(nib.load(f'{d}/truth_gm.nii.gz').dataobj) > 0
    mask = np.asarray(nib.load(f'{d}/{seg}').dataobj) > 0
    if truth.shape != mask.shape:
        sys.exit('phantom_topology: the mask and the truth differ in size')
    lab, n = ndi.label(np.pad(~truth, 1, constant_values=True))  # 6-connected; the padding joins the border regions
    sizes = np.bincount(lab.ravel())
    sizes[lab[0, 0, 0]] = 0
    sizes[0] = 0
    core = (lab == int(np.argmax(sizes)))[1:-1, 1:-1, 1:-1]
    b0 = ndi.label(mask, np.ones((3, 3, 3)))[1]
    bg, nb = ndi.label(np.pad(~mask, 1, constant_values=True))
    outside = bg[0, 0, 0]
    b2 = nb - 1
    b1 = b0 + b2 - euler26(mask)
    bg = bg[1:-1, 1:-1, 1:-1]
    # the region of the mask's outside holding most of the core's unsegmented voxels
    main_region = int(np.argmax(np.bincount(bg[core & ~mask].ravel(), minlength=nb + 1)[1:])) + 1
    sealed = main_region != outside
    bubbles = b2 - int(sealed)
    print(f"{b0} {b1} {b2} core {'sealed' if sealed else 'open'} bubbles {bubbles}")


if __name__ == '__main__':
    main()
