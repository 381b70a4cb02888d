#!/usr/bin/python3
# BrainWeb variants acquired as clinical and public datasets are (docs/BENCHMARKS.md, session 60): thick
# slices whose voxels average their slab (MRBrainS-like 0.96 x 0.96 x 3 mm axial, IBSR-like 1.5 mm
# coronal), a 0.7 mm grid (HCP-like), 8-bit storage. Each in OUT/NAME/{t1,labels,mask}.nii.gz.
# Usage: /usr/bin/python3 scripts/brainweb_slab_variants.py OUT_DIR  (Debian's python3-nibabel, -scipy)
#    or: /usr/bin/python3 scripts/brainweb_slab_variants.py --unoriented VARIANT_DIR OUT_DIR
#        the variant stored as a coronal stack (left-right, superior -> inferior, posterior -> anterior)
#        with qform and sform codes 0, as IBSR's scans; OUT_DIR/seeds holds the 8 seeds (given
#        in mm) as voxels of that stack, which scripts/variant_dice.sh then uses.
import os, sys
import nibabel as nib, numpy as np
from scipy import ndimage
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import brainweb_data

SEEDS_MM = [(35, 83, 113), (35, 125, 38), (44, 164, 92), (71, 74, 53), (122, 149, 47), (140, 86, 74), (38, 71, 26), (83, 23, 71)]


def unoriented(src, dst):
    os.makedirs(dst, exist_ok=True)
    img = nib.load(os.path.join(src, 't1.nii.gz'))
    lps = np.diag([-1, -1, 1, 1]) @ img.affine
    seeds = []
    for s in SEEDS_MM:
        i, j, k = np.round(np.linalg.solve(lps, np.array([*s, 1.0]))[:3]).astype(int)
        seeds.append('--seed %d,%d,%d' % (i, img.shape[2] - 1 - k, j))
    with open(os.path.join(dst, 'seeds'), 'w') as f:
        f.write(' '.join(seeds) + '\n')
    z = img.header.get_zooms()
    for name in ('t1', 'labels', 'mask'):
        a = np.asarray(nib.load(os.path.join(src, name + '.nii.gz')).dataobj)
        a = np.ascontiguousarray(np.transpose(a, (0, 2, 1))[:, ::-1, :])
        h = nib.Nifti1Header(); h.set_data_dtype(a.dtype); h.set_data_shape(a.shape); h.set_zooms((z[0], z[2], z[1]))
        im = nib.Nifti1Image(a, None, h); im.header.set_qform(None, code=0); im.header.set_sform(None, code=0)
        nib.save(im, os.path.join(dst, name + '.nii.gz'))
    print(dst, a.shape)


if len(sys.argv) == 4 and sys.argv[1] == '--unoriented':
    unoriented(sys.argv[2], sys.argv[3])
    sys.exit(0)
out = sys.argv[1] if len(sys.argv) > 1 else 'brainweb-slab-variants'
t1, labels, mask, base = brainweb_data.load()
n = np.array(t1.shape, float)
rng = np.random.default_rng(60)
def rician(a, s): return np.sqrt((a + rng.normal(0, s, a.shape))**2 + rng.normal(0, s, a.shape)**2)
def save(name, T, L, M, aff, dtype=np.float32):
    d = os.path.join(out, name); os.makedirs(d, exist_ok=True)
    nib.save(nib.Nifti1Image(T.astype(dtype), aff), os.path.join(d, 't1.nii.gz'))
    nib.save(nib.Nifti1Image(L.astype(np.uint8), aff), os.path.join(d, 'labels.nii.gz'))
    nib.save(nib.Nifti1Image(M.astype(np.uint8), aff), os.path.join(d, 'mask.nii.gz'))
    print(name, T.shape, flush=True)
def res(h, slab=None):
    """Resample to spacing h (mm); with `slab`, each voxel averages a box of its own size first
    (a thick slice's partial volume), the labels take the slab centre's."""
    h = np.array(h, float); m = np.diag(h)
    shape = tuple(int(v) for v in np.floor((n - 1) / h) + 1)
    aff = base @ np.block([[m, np.zeros((3, 1))], [np.zeros((1, 3)), np.ones((1, 1))]])
    r = lambda a, o: ndimage.affine_transform(a, m, output_shape=shape, order=o)
    T = t1 if slab is None else ndimage.uniform_filter(t1, size=[max(1, int(round(v))) for v in h])
    return r(T, 1), r(labels, 0), r(mask, 0), aff
T, L, M, a = res([0.96, 0.96, 3.0], slab=True)
save('slab3ax', T, L, M, a); save('slab3axr', rician(T, 7), L, M, a)
T, L, M, a = res([0.94, 1.5, 0.94], slab=True); save('cor15r', rician(T, 7), L, M, a)
T, L, M, a = res([0.7, 0.7, 0.7]); save('hr07r', rician(T, 6), L, M, a)
save('uint8r', np.clip(np.round(rician(t1, 7) * 255 / 300), 0, 255), labels, mask, base, np.uint8)
