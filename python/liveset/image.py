"""Images as numpy arrays with their geometry (spacing, origin, direction; LPS like ITK), and
conversion to and from nibabel images (whose affines are RAS)."""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

# LPS (ITK, liveset) <-> RAS (nibabel, NIfTI affines): negate the first two world axes.
_LPS_RAS = np.diag([-1.0, -1.0, 1.0, 1.0])


@dataclass
class Image:
    """A 3D image: ``array[i, j, k]`` (i along the image's first axis, as ITK, nibabel and
    SimpleITK index voxels) and its physical placement in LPS millimetres, as ITK has it:
    ``world = origin + direction @ (spacing * [i, j, k])``.

    ``direction`` is a 3x3 matrix whose columns are the axes in LPS world space. Arrays returned by
    liveset are Fortran-ordered views on the C++ result (no copy).

    ``oriented`` is False when the file gave no orientation (a NIfTI with neither qform nor sform,
    an Analyze file): its axes are then LPS identity, as ITK reads them, which may not say where the
    head's top is; the automatic brain mask then finds it from the head (the neck)."""

    array: np.ndarray
    spacing: tuple = (1.0, 1.0, 1.0)
    origin: tuple = (0.0, 0.0, 0.0)
    direction: np.ndarray = field(default_factory=lambda: np.eye(3))
    oriented: bool = True

    def __post_init__(self):
        self.array = np.asarray(self.array)
        if self.array.ndim != 3:
            raise ValueError(f"an Image needs a 3D array, not shape {self.array.shape}")
        self.spacing = tuple(float(s) for s in np.ravel(self.spacing))
        self.origin = tuple(float(o) for o in np.ravel(self.origin))
        self.direction = np.asarray(self.direction, dtype=float).reshape(3, 3)
        if len(self.spacing) != 3 or len(self.origin) != 3:
            raise ValueError("spacing and origin need 3 numbers each")

    @property
    def shape(self):
        return self.array.shape

    @property
    def geometry(self):
        """(spacing, origin, direction) as the C++ core takes it."""
        return (self.spacing, self.origin, self.direction)

    @property
    def affine_lps(self) -> np.ndarray:
        """4x4 voxel -> LPS mm matrix."""
        a = np.eye(4)
        a[:3, :3] = self.direction * np.asarray(self.spacing)[None, :]
        a[:3, 3] = self.origin
        return a

    @property
    def affine(self) -> np.ndarray:
        """4x4 voxel -> RAS mm matrix (nibabel's convention)."""
        return _LPS_RAS @ self.affine_lps

    def like(self, array) -> "Image":
        """Another image on this one's geometry."""
        return Image(array, self.spacing, self.origin, self.direction.copy(), self.oriented)

    def same_geometry(self, other: "Image", tol: float = 1e-4) -> bool:
        return (self.shape == other.shape and np.allclose(self.spacing, other.spacing, atol=tol)
                and np.allclose(self.origin, other.origin, atol=tol)
                and np.allclose(self.direction, other.direction, atol=tol))

    @classmethod
    def from_affine(cls, array, affine) -> "Image":
        """From an array and a nibabel (RAS) affine."""
        lps = _LPS_RAS @ np.asarray(affine, dtype=float)
        m = lps[:3, :3]
        spacing = np.linalg.norm(m, axis=0)
        if np.any(spacing <= 0) or not np.all(np.isfinite(lps)):
            raise ValueError("the affine has a zero or non-finite axis")
        return cls(array, spacing, lps[:3, 3], m / spacing[None, :])

    @classmethod
    def from_nibabel(cls, img) -> "Image":
        """From a nibabel image (Nifti1Image, Nifti2Image, MGHImage, ...): its data as float32
        (labels keep their integer type) and its affine."""
        data = np.asanyarray(img.dataobj)  # scaled (scl_slope/scl_inter) data come out as floats
        if data.ndim == 4 and data.shape[3] == 1:
            data = data[..., 0]
        if not np.issubdtype(data.dtype, np.integer):
            data = np.asarray(data, dtype=np.float32)
        out = cls.from_affine(data, img.affine)
        import nibabel as nib
        if isinstance(img, (nib.Nifti1Image, nib.Nifti2Image, nib.Nifti1Pair, nib.Nifti2Pair)):
            out.oriented = bool(int(img.header["qform_code"]) or int(img.header["sform_code"]))
        elif isinstance(img, nib.AnalyzeImage):  # the NIfTI classes derive from it: after them
            out.oriented = False
        return out

    def to_nibabel(self, dtype=None):
        """A nibabel Nifti1Image with this image's affine (RAS), qform and sform set."""
        import nibabel as nib
        data = np.asarray(self.array if dtype is None else self.array.astype(dtype))
        if data.dtype == bool:
            data = data.astype(np.uint8)
        img = nib.Nifti1Image(data, self.affine)
        img.set_qform(self.affine, code=1)
        img.set_sform(self.affine, code=1)
        return img


def as_image(x, what="image") -> Image:
    """An Image from an Image, a nibabel image, or a (array, affine) pair."""
    if isinstance(x, Image):
        return x
    if hasattr(x, "affine") and hasattr(x, "dataobj"):
        return Image.from_nibabel(x)
    if isinstance(x, tuple) and len(x) == 2:
        return Image.from_affine(*x)
    raise TypeError(f"{what}: expected a liveset.Image, a nibabel image or (array, affine), "
                    f"not {type(x).__name__}")
