"""The bundled BrainWeb T1, its crisp labels, brain mask and affine, for the variant scripts
(brainweb_variants.py, brainweb_geometry.py, brainweb_noise_variants.py, brainweb_ventricle_variants.py,
brainweb_atrophy_variants.py and the others). nibabel + numpy."""
import os
import zlib

import nibabel as nib
import numpy as np

HERE = os.path.join(os.path.dirname(os.path.abspath(__file__)), '..', 'data', 'brainweb')


def load():
    """(t1 float32 in BrainWeb's voxel order, labels uint8, brain mask uint8 0/1, RAS affine)."""
    raw = open(os.path.join(HERE, 't1.mha'), 'rb').read()
    start = raw.index(b'ElementDataFile = LOCAL\n') + len(b'ElementDataFile = LOCAL\n')
    t1 = np.frombuffer(zlib.decompress(raw[start:]), dtype=np.uint8).reshape(180, 217, 181).transpose(2, 1, 0).astype(np.float32)
    labels_img = nib.load(os.path.join(HERE, 'labels_crisp.nii.gz'))
    labels = np.asarray(labels_img.dataobj).astype(np.uint8)
    mask = (np.asarray(nib.load(os.path.join(HERE, 'brain_mask.nii.gz')).dataobj) > 0).astype(np.uint8)
    return t1, labels, mask, labels_img.affine
