#!/usr/bin/python3
# Writes the BrainWeb T1 times a smooth multiplicative field spanning 1 +- AMPLITUDE inside the brain
# mask, as float32 NIfTI with the labels' affine (the bias-correction benchmark in docs/BENCHMARKS.md).
# Usage: /usr/bin/python3 scripts/brainweb_bias_variant.py OUT.nii.gz [AMPLITUDE=0.25]
# Also writes OUT_field.nii.gz (the field). Needs Debian's python3 with numpy and nibabel.
import os
import sys
import zlib

import nibabel as nib
import numpy as np

DATA = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "data", "brainweb")


def read_metaimage(path):
    """The bundled t1.mha: a zlib-compressed uint8 MetaImage (nibabel cannot read MetaImage)."""
    raw = open(path, "rb").read()
    end = raw.index(b"ElementDataFile = LOCAL\n") + len(b"ElementDataFile = LOCAL\n")
    header = dict(line.split(" = ", 1) for line in raw[:end].decode().splitlines())
    if header["ElementType"] != "MET_UCHAR" or header["NDims"] != "3" or header["TransformMatrix"] != "1 0 0 0 1 0 0 0 1":
        sys.exit(f"{path}: unexpected MetaImage header {header}")
    dims = [int(d) for d in header["DimSize"].split()]
    data = raw[end:]
    if header.get("CompressedData") == "True":
        data = zlib.decompress(data)
    # MetaImage stores x fastest; nibabel arrays are indexed [i, j, k].
    return np.frombuffer(data, np.uint8).reshape(dims[::-1]).transpose(2, 1, 0).astype(np.float64)


def main():
    if len(sys.argv) not in (2, 3):
        sys.exit("usage: brainweb_bias_variant.py OUT.nii.gz [AMPLITUDE=0.25]")
    out = sys.argv[1]
    amplitude = float(sys.argv[2]) if len(sys.argv) == 3 else 0.25
    t1 = read_metaimage(os.path.join(DATA, "t1.mha"))
    labels = nib.load(os.path.join(DATA, "labels_crisp.nii.gz"))
    brain = np.asarray(nib.load(os.path.join(DATA, "brain_mask.nii.gz")).dataobj) > 0
    if t1.shape != labels.shape or t1.shape != brain.shape:
        sys.exit(f"shapes differ: t1 {t1.shape}, labels {labels.shape}, mask {brain.shape}")
    nx, ny, nz = t1.shape
    x, y, z = np.meshgrid(np.linspace(-1, 1, nx), np.linspace(-1, 1, ny), np.linspace(-1, 1, nz), indexing="ij")
    q = 0.6 * x + 0.5 * z - 0.4 * y**2 + 0.3 * x * y  # left-right and inferior-superior gradients, a bowl
    q = 2 * (q - q[brain].min()) / (q[brain].max() - q[brain].min()) - 1  # [-1, 1] over the brain
    field = 1 + amplitude * q
    if field.min() <= 0:
        sys.exit("the field reaches zero outside the brain: lower AMPLITUDE")
    nib.save(nib.Nifti1Image((t1 * field).astype(np.float32), labels.affine), out)
    stem = out[: -len(".nii.gz")] if out.endswith(".nii.gz") else os.path.splitext(out)[0]
    nib.save(nib.Nifti1Image(field.astype(np.float32), labels.affine), stem + "_field.nii.gz")
    print(f"{out}: field {field[brain].min():.3f}..{field[brain].max():.3f} in the brain "
          f"(geometric mean {np.exp(np.log(field[brain]).mean()):.4f}), {field.min():.3f}..{field.max():.3f} overall")


if __name__ == "__main__":
    main()
