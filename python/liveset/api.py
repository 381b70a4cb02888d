"""liveset's functions on images in memory: read/write through the C++ IO, segment (as
``liveset segment``), the tissue model and window, mesh, evaluate and repair."""
from __future__ import annotations

import json
from dataclasses import dataclass
from typing import Callable, Optional, Sequence

import numpy as np

from . import _liveset
from .image import Image, as_image

ImageIOError = _liveset.ImageIOError


def read(path: str, labels: bool = False) -> Image:
    """Read a 3D image (NIfTI, MetaImage, NRRD, MINC, a DICOM folder) through liveset's C++ IO.

    Returns float32 intensities, or uint8 labels with ``labels=True`` (values must be 0..255).
    NaN voxels (a masked image's "no data": SPM, ``fslmaths -nan``) stay NaN, as nibabel reads
    them (a NIfTI's too); ``segment``, ``Session`` and the hole tools read them as lying below every
    other value, outside the brain. Raises ImageIOError (an OSError) with a one-line message on
    missing, corrupt, 2D, RGB, ... files, and on infinite voxels."""
    array, (spacing, origin, direction), oriented = _liveset._read(str(path), labels)
    return Image(array, spacing, origin, direction, oriented)


def read_header(path: str) -> dict:
    """What an image file says about itself, without reading the voxels: dims, spacing, origin
    (LPS), direction (9 numbers, row-major), dimension, components, pixel_type, format, oriented
    (False: a NIfTI without qform and sform, or an Analyze file; see Image.oriented)."""
    return _liveset._read_header(str(path))


def write(image, path: str, labels: bool = False) -> None:
    """Write an image atomically (temporary + rename) with its full geometry; the format follows
    the extension (.nii.gz, .nii, .mha, .nrrd, .mnc, ...). ``labels=True`` writes uint8 0..255 (a
    mask: non-zero -> 1); otherwise float32. An image without orientation (``Image.oriented``
    False: read from a NIfTI without qform and sform, or an Analyze file) is written as one (a
    NIfTI's qform and sform codes 0), so nibabel and FSL place it where they place its source."""
    img = as_image(image)
    _liveset._write(img.array, img.geometry, str(path), labels, bool(img.oriented))


def _seed_text(seed) -> str:
    if isinstance(seed, str):
        return seed
    s = [float(v) for v in seed]
    if len(s) not in (3, 4):
        raise ValueError(f"a seed is (i, j, k) or (i, j, k, radius), not {seed!r}")
    text = ",".join(repr(v) for v in s[:3])
    return text + (f":{s[3]!r}" if len(s) == 4 else "")


@dataclass
class Segmentation:
    """What ``segment`` returns: ``mask`` (uint8 0/1, φ < 0 within the ROI), ``phi`` (float32,
    < 0 inside), ``report`` (the dict ``liveset segment --json`` prints: iterations, stop, window,
    tissue model, volume, ``no_data_voxels``: the image's NaN voxels, ...), ``roi`` when one was
    used, ``corrected`` when N4 ran (the default: the image the segmentation saw, NaN again where
    the image had NaN)."""
    mask: Image
    phi: Image
    report: dict
    roi: Optional[Image] = None
    corrected: Optional[Image] = None


def segment(image, seeds: Sequence = (), *, seeds_mm: Sequence = (), seed_radius: float = 2.0,
            roi=None, init_mask=None, mu: Optional[float] = None, epsilon: Optional[float] = None,
            mu_raw: Optional[float] = None, epsilon_raw: Optional[float] = None,
            window_from: str = "model", classes: int = 3, n: float = 4.0, alpha: Optional[float] = None,
            smooth_mm: Optional[float] = None, iterations: int = 2000, bias_correct: Optional[bool] = None,
            thin_fronts: bool = _liveset.DEFAULT_THIN_FRONTS, coarse_start: str = "auto",
            progress: Optional[Callable[[dict], None]] = None) -> Segmentation:
    """Threshold level-set segmentation from seeds (paper Eq. 2-3), exactly as ``liveset segment``
    with the same options (the same image and options give the same mask, bit for bit).

    image: a liveset.Image, a nibabel image or (array, RAS affine).
    seeds: voxel indices ``(i, j, k)``, ``(i, j, k, radius)`` or the CLI's ``"I,J,K[:R]"``
        strings (0-based, radius in voxels); seeds_mm: LPS mm ``"X,Y,Z[:R]"`` (radius in mm).
    roi: None (the default: the automatic brain mask when the image is a full head, else none; a
        seed whose ball lies wholly outside it is left out with a warning naming ``roi="none"``,
        and when more than half of them do - or over 5 % of ``init_mask`` lies outside - the whole image is
        segmented, warned), ``"auto"`` (the automatic brain mask, an error when none is found),
        ``"none"`` (the whole image) or a mask (Image/nibabel/array) the front may not leave. Any
        ROI leaves out seeds wholly outside it (warned); all of them outside is a ValueError.
        init_mask: start from this region instead of seeds.
    mu/epsilon: the window in normalised units, or mu_raw/epsilon_raw in the image's own; by
        default the tissue model's window for the seeds' class (``window_from="seeds"``: their
        statistics). n, alpha, iterations, classes: as the CLI (alpha None: chosen
        from the image, the report's "alpha_choice" says how). smooth_mm: the σ in mm of the
        image's blur before the threshold term, only with alpha (None: 0 with a given alpha; the
        automatic alpha chooses it, half the finest voxel side on a noisy scan). bias_correct: None (the default)
        runs N4 first as ``liveset segment`` does, skipped with a report warning where it cannot run
        (an image too small for its grid); True requires it (ValueError where it cannot run); False
        turns it off. thin_fronts: the thin-front rule, which lets the front into tissue one or two
        voxels thick (on by default since session 72, as the CLI's; ``False`` as ``--no-thin-fronts``,
        the paper's sparse field; docs/ARCHITECTURE.md, "Thin fronts"). coarse_start: as
        ``--coarse-start``: ``"auto"`` (the default) lets the front from seeds on a grid whose voxel
        sides are all at most 0.85 mm converge first on 2x2x2-voxel blocks (their mean threshold term) and
        refine from there; ``"on"`` wherever it starts from seeds on a grid of at least 16 voxels an axis; ``"off"`` never (the report's
        "coarse_start" says what ran; docs/ARCHITECTURE.md, "Coarse start").
    progress: called with a dict (iteration, zero_layer, band, awake, changed, flips, inside, dt, ms,
        level: "coarse" for the coarse start's steps, else "fine") after every step; an exception it
        raises stops the run and propagates.

    The GIL is released while it runs; Ctrl-C raises KeyboardInterrupt within a step. Bad input
    raises ValueError (ImageIOError for files) with a one-line message."""
    img = as_image(image)
    kw = dict(seeds=[_seed_text(s) for s in seeds], seeds_mm=[_seed_text(s) for s in seeds_mm],
              seed_radius=float(seed_radius), mu=mu, epsilon=epsilon, mu_raw=mu_raw,
              epsilon_raw=epsilon_raw, window_from=window_from, classes=int(classes), n=float(n),
              alpha=None if alpha is None else float(alpha),
              smooth_mm=None if smooth_mm is None else float(smooth_mm), iterations=int(iterations),
              bias_correct=None if bias_correct is None else bool(bias_correct), oriented=bool(img.oriented),
              thin_fronts=bool(thin_fronts), coarse_start=str(coarse_start))
    kw["roi"] = _mask_arg(roi, img, "roi", allow_auto=True)
    kw["init_mask"] = _mask_arg(init_mask, img, "init_mask")
    r = _liveset._segment(img.array, img.geometry, progress, **kw)
    return Segmentation(mask=img.like(r["mask"]), phi=img.like(r["phi"]), report=json.loads(r["report"]),
                        roi=img.like(r["roi"]) if "roi" in r else None,
                        corrected=img.like(r["corrected"]) if "corrected" in r else None)


def _mask_arg(mask, img: Image, what: str, allow_auto: bool = False):
    if mask is None:
        return None
    if isinstance(mask, str):
        if allow_auto and mask in ("auto", "none"):
            return mask
        raise ValueError(f"{what} must be {'auto, none, ' if allow_auto else ''}a mask image or array, not {mask!r}")
    if isinstance(mask, np.ndarray):
        arr = mask
    else:
        m = as_image(mask, what)
        if not m.same_geometry(img):
            raise ValueError(f"{what} does not overlay the image (shape, spacing, origin or direction differ)")
        arr = m.array
    if arr.shape != img.shape:
        raise ValueError(f"{what} has shape {arr.shape}, the image {img.shape}")
    return np.asarray(arr)


def tissue_model(image, seeds: Sequence = (), *, seeds_mm: Sequence = (), seed_radius: float = 2.0,
                 roi=None, classes: int = 3, window_from: str = "model",
                 bias_correct: Optional[bool] = None) -> dict:
    """The tissue model (a mixture of tissue classes with partial volume) fitted where ``segment`` fits it,
    on the image ``segment`` fits it on (bias-corrected as there: ``bias_correct`` as in
    ``segment``), and, with seeds, the threshold window ``segment`` would use: a dict with
    ``intensity_scale``, ``tissue_model`` (classes: name, mean, sigma, weight; seed_class; contrast:
    "T1" or "grey brighter than white (T2, PD)" where the region is a whole brain or the image reads
    grey brighter (off its brain or, with a ROI given as a mask, its head; before N4 too), naming the
    classes CSF, GM, WM or WM, GM, CSF from dark to bright, else None; floor: where grey is brighter
    than white, the value below which the region's voxels, darker than white matter, were left out
    of the fit, else None),
    ``window`` (mu, epsilon normalised; mu_raw, epsilon_raw, lower_raw, upper_raw; source),
    ``warnings`` and, when N4 ran, ``bias_correction``."""
    img = as_image(image)
    kw = dict(seeds=[_seed_text(s) for s in seeds], seeds_mm=[_seed_text(s) for s in seeds_mm],
              seed_radius=float(seed_radius), classes=int(classes), window_from=window_from,
              roi=_mask_arg(roi, img, "roi", allow_auto=True),
              bias_correct=None if bias_correct is None else bool(bias_correct), oriented=bool(img.oriented))
    return json.loads(_liveset._tissue_model(img.array, img.geometry, **kw))


@dataclass
class Mesh:
    """A triangle mesh in LPS millimetres: vertices (N, 3), faces (M, 3) vertex indices, unit
    normals (N, 3) pointing outwards (towards φ > 0)."""
    vertices: np.ndarray
    faces: np.ndarray
    normals: np.ndarray


def mesh(phi_or_mask, out: Optional[str] = None, kind: str = "auto") -> Mesh:
    """Marching cubes of a φ image (< 0 inside) or of a 0/1 mask (as ``liveset mesh``), in LPS mm.
    ``out``: also write it (.ply, .obj or .stl). kind: "auto", "phi" or "mask"."""
    img = as_image(phi_or_mask)
    if kind not in ("auto", "phi", "mask"):
        raise ValueError(f"kind must be auto, phi or mask, not {kind!r}")
    a = img.array
    is_mask = kind == "mask" or (kind == "auto" and (a.dtype == bool or np.all((a == 0) | (a == 1))))
    v, f, nrm = _liveset._mesh(a, img.geometry, bool(is_mask), "" if out is None else str(out))
    return Mesh(v, f, nrm)


def evaluate(mask, truth, label=None) -> dict:
    """``liveset eval``'s metrics of a mask against a truth: dice, jaccard, volume_difference,
    hausdorff95_mm, hausdorff_mm, mean_surface_mm, components, euler, genus, cavities, holes and
    the truth's topology. ``label``: use truth == label (e.g. 2 = grey matter in BrainWeb); a
    sequence of labels is one structure (FreeSurfer's aseg cortex: ``(3, 42)``)."""
    m, t = as_image(mask, "mask"), as_image(truth, "truth")
    if not m.same_geometry(t):
        raise ValueError("the mask and the truth do not share a geometry (shape, spacing, origin or direction)")
    ta = np.asarray(t.array)
    labels = None if label is None else [int(v) for v in (label if np.ndim(label) else [label])]
    ta = np.isin(ta, labels) if labels is not None else (ta != 0)
    if labels is not None and not ta.any():
        raise ValueError(f"the truth has no voxel with label {','.join(map(str, labels))}")
    return json.loads(_liveset._evaluate(np.asarray(m.array) != 0, ta, m.geometry))


def find_holes(mask, image, roi=None, sheet_band=None, min_voxels: int = 10, min_sheet_share: float = 0.1) -> dict:
    """``liveset holes``: holes of a segmented sheet found without ground truth — unsegmented voxels
    that look like the sheet's tissue where the tissue it encloses meets the outside.

    ``mask`` the segmentation (non-zero inside) or a φ image (< 0 inside is not assumed: pass a
    mask), ``image`` the image the segmentation came from on the same grid (``segment(...).corrected``
    when N4 ran, the default), ``roi`` optional. ``sheet_band=(lower, upper)``
    in raw intensities; by default the tissue model's band of the sheet's class. Returns
    ``{"sheet_band", "band_from", "holes": [{"voxels", "rim", "sheet", "target": [i, j, k],
    "centroid"}, ...] (largest first), "warnings"}``; a ``target`` is what ``repair`` and
    ``liveset repair --target`` take."""
    m, img = as_image(mask, "mask"), as_image(image, "image")
    if not m.same_geometry(img):
        raise ValueError("the mask and the image do not share a geometry (shape, spacing, origin or direction)")
    r = None
    if roi is not None:
        ri = as_image(roi, "roi")
        if not ri.same_geometry(img):
            raise ValueError("the roi and the image do not share a geometry (shape, spacing, origin or direction)")
        r = np.asarray(ri.array) != 0
    band = None if sheet_band is None else (float(sheet_band[0]), float(sheet_band[1]))
    return json.loads(_liveset._find_holes(np.asarray(m.array) != 0, np.asarray(img.array, dtype=np.float32), r,
                                           m.geometry, band, int(min_voxels), float(min_sheet_share), bool(img.oriented)))


def set_threads(threads: int) -> None:
    """Limit liveset's worker threads (0: all cores). Results are identical for any count."""
    _liveset.set_threads(int(threads))
