"""Scripted interactive work: ``Session`` (seeds, segmentation steps, swarm repair, undo/redo),
the same session the viewer drives, and ``repair`` on top of it."""
from __future__ import annotations

import json
import warnings
from typing import Optional, Sequence

import numpy as np

from . import _liveset
from .api import _mask_arg
from .image import Image, as_image


class Session:
    """An editing session on one image: seeds, threshold parameters, the sparse-field level set,
    the swarm and an undo history of at least 20 actions (bit-identical undo).

    >>> s = liveset.Session(img, roi=brain)      # img: Image or nibabel image
    >>> s.add_seed((60, 64, 64)); s.run(500)     # grow until converged (or 500 steps)
    >>> s.set_target((70, 64, 64)); s.swarm(100) # repair where you point
    >>> s.undo(); m = s.mask()

    Coordinates are voxel indices (i, j, k). Runs release the GIL and stop on Ctrl-C between
    steps (KeyboardInterrupt; the steps taken so far stay and can be undone).

    The image is prepared as ``liveset view`` and ``segment`` prepare it: ``bias_correct=None``
    (the default) runs N4 first, fitted in the ROI or else the automatic brain mask, and skips it
    with a warning where it cannot run (an image too small for its grid); True requires it
    (ValueError where it cannot run); False takes the image as given (pass False for an image that
    is already corrected, e.g. ``segment(...).corrected``). Without a ROI the tissue model is
    fitted in the automatic brain mask (found again on the corrected image), as ``segment`` fits it, so the same seeds give
    ``segment``'s mask, bit for bit, with the same ``coarse_start``: ``"auto"`` (the default), ``"on"`` or
    ``"off"`` as ``segment``'s. Where it applies (from seeds, on a grid of voxels at most 0.85 mm), the
    first steps are the coarse start's iterations on 2x2x2-voxel blocks (``status["coarse"]`` True,
    ``status["coarse_iterations"]`` counting them, φ unchanged), the one that ends that run puts its
    upsampled front (less the voxels the image's own data term refuses) in place of the seeds, and the steps after it refine on the image's grid
    (``status["iterations"]``); ``step(n)`` takes n steps of either kind, ``run``'s ``max_steps``
    bounds the image's grid's steps as ``segment``'s ``iterations`` bounds each stage. ``roi``: as ``segment``'s: None (the automatic brain mask when the image is
    a head, else none), ``"auto"``, ``"none"`` or a mask (Image, nibabel image or array) the front
    may not leave. ``image`` is the
    image the session works on (the corrected one when N4 ran; NaN voxels, a masked image's "no
    data", lowered below the rest as ``segment`` reads them), ``corrected`` True when N4 ran,
    ``roi`` the ROI as an Image (None without one), ``report`` the ``bias_correction`` (or
    ``warnings``) and ``roi`` entries of ``segment``'s report.

    ``alpha=None`` (the default) chooses the curvature weight as ``segment`` does (from the tissue
    model's noise over the window's contrast and the voxel shape) once there is a window (the first
    seed, ``set_params`` or the first step; ``params["alpha"]`` shows 0.1 until then) and again
    whenever the seeds move the window, with the pre-smoothing (``params["smooth_mm"]``: the σ in mm
    of the blur of the image the threshold term reads, half the finest voxel side on a noisy scan);
    a number fixes it (0.1 is the paper's), and ``smooth_mm`` then sets the blur (default 0).
    ``thin_fronts`` (on by default since session 72, as ``segment``'s) lets the front into tissue one
    or two voxels thick; ``False`` as ``--no-thin-fronts``."""

    def __init__(self, image, roi=None, *, n: float = 4.0, alpha: Optional[float] = None,
                 smooth_mm: Optional[float] = None, layers: int = 2,
                 fragment_size: int = 16, history: int = 32, agents: int = 200, p: float = 0.1,
                 seed: int = 1, sleeping: bool = True, decision: str = "intensity",
                 edit_range: Optional[float] = None, bias_correct: Optional[bool] = None,
                 thin_fronts: bool = _liveset.DEFAULT_THIN_FRONTS, coarse_start: str = "auto"):
        img = as_image(image)
        if decision not in ("intensity", "random", "cut") or int(agents) < 1:  # before N4's seconds
            raise ValueError("decision must be 'intensity', 'random' or 'cut', and agents at least 1")
        if coarse_start not in ("auto", "on", "off"):
            raise ValueError(f"coarse_start must be 'auto', 'on' or 'off', not {coarse_start!r}")
        if smooth_mm is not None and alpha is None:
            raise ValueError("smooth_mm needs alpha: the automatic choice sets both")
        prepared = _liveset._prepare_session_image(img.array, img.geometry, _mask_arg(roi, img, "roi", allow_auto=True),
                                                   None if bias_correct is None else bool(bias_correct), bool(img.oriented))
        self.corrected = bool(prepared["corrected"])
        self.image = img if prepared["image"] is None else img.like(prepared["image"])  # corrected, or its NaN lowered
        self.roi = None if prepared["roi"] is None else img.like(prepared["roi"])
        self.report = json.loads(prepared["report"])
        self._s = _liveset._Session(self.image.array, img.geometry, prepared["roi"], prepared["model_region"],
                                    bool(prepared["region_is_brain"]), bool(prepared["region_grey_brighter"]), float(n),
                                    None if alpha is None else float(alpha),
                                    None if smooth_mm is None else float(smooth_mm), int(layers),
                                    int(fragment_size), int(history), int(agents), float(p), int(seed),
                                    bool(sleeping), str(decision),
                                    float(_edit_range(decision, edit_range)), bool(img.oriented), bool(thin_fronts),
                                    str(coarse_start))

    # seeds and parameters
    def add_seed(self, ijk: Sequence[float], radius: float = 2.0) -> None:
        """Add a seed ball (undoable); the window follows the seeds unless set_params fixed it."""
        try:
            self._s.add_seed([float(v) for v in ijk], float(radius))
        except ValueError as e:
            if self.report.get("roi", {}).get("default"):
                raise ValueError(f"{e}: the automatic brain mask bounds the front by default on a head; "
                                 "pass roi='none' to segment outside the brain") from None
            raise

    def remove_seed(self, index: int) -> None:
        self._s.remove_seed(int(index))

    @property
    def seeds(self):
        """[(i, j, k, radius), ...]"""
        return self._s.seeds()

    def set_params(self, mu: Optional[float] = None, epsilon: Optional[float] = None,
                   n: Optional[float] = None, alpha=None, smooth_mm: Optional[float] = None) -> None:
        """Set n, alpha and the window (normalised units). Without mu and epsilon the window stays
        as it was: following the seeds (the tissue model's window, as ``liveset segment``) or as
        set. alpha: a number fixes it, ``"auto"`` chooses it and the pre-smoothing as ``segment``
        does, None keeps the current choice. smooth_mm: the blur's σ in mm, with a fixed alpha
        (None keeps the current value; 0 when alpha goes from automatic to a number, as
        ``segment(alpha=...)``)."""
        p = self.params
        from_seeds = p["window_from_seeds"] if mu is None and epsilon is None else False
        automatic = p["alpha_automatic"] if alpha is None else (isinstance(alpha, str) and alpha == "auto")
        if isinstance(alpha, str) and alpha != "auto":
            raise ValueError(f"alpha must be a number or 'auto', not {alpha!r}")
        if smooth_mm is not None and automatic:
            raise ValueError("smooth_mm needs a fixed alpha: the automatic choice sets both")
        if smooth_mm is None and p["alpha_automatic"] and not automatic:
            smooth_mm = 0.0  # a given alpha: no blur unless given, as segment(alpha=...)
        self._s.set_params(p["mu"] if mu is None else float(mu), p["epsilon"] if epsilon is None else float(epsilon),
                           p["n"] if n is None else float(n), p["alpha"] if alpha is None or automatic else float(alpha),
                           p["smooth_mm"] if smooth_mm is None else float(smooth_mm), from_seeds, automatic)

    @property
    def params(self) -> dict:
        """mu, epsilon (normalised), mu_raw, epsilon_raw, n, alpha, smooth_mm, window_from_seeds,
        alpha_automatic."""
        return self._s.params()

    # segmentation and repair
    def step(self, steps: int = 1) -> dict:
        """Take `steps` segmentation steps (one undoable action); returns the status and
        ``warnings`` (see ``run``)."""
        return _warned(self._s.segment_steps(int(steps), False))

    def run(self, max_steps: int = 2000) -> dict:
        """Segmentation steps until the front converges (or vanishes), at most max_steps on the
        image's grid (the coarse start's iterations before them, where it runs, are bounded by its
        own limit of 2000, as ``segment``'s); returns
        the status and ``warnings``: with ``roi="none"`` on a head, a converged front with more
        than 5 % of its voxels outside the automatic brain mask is warned about as ``segment`` warns
        (also issued as a Python ``UserWarning``); the default ROI (or ``roi="auto"``) keeps brain
        tissue in."""
        return _warned(self._s.segment_steps(int(max_steps), True))

    @property
    def status(self) -> dict:
        """iterations, converged, vanished, flips, inside, dt, zero_layer; coarse (the last step was
        the coarse start's), coarse_iterations, coarse_inside (its blocks inside)."""
        return self._s.status()

    def set_target(self, ijk: Sequence[float]) -> None:
        """Aim the swarm at a point (voxel indices) near the surface, e.g. a hole."""
        self._s.set_target([float(v) for v in ijk])

    def clear_target(self) -> None:
        self._s.clear_target()

    def swarm(self, steps: int = 1) -> dict:
        """`steps` swarm steps towards the target (one undoable action)."""
        return self._s.swarm_steps(int(steps))

    @property
    def agents(self) -> np.ndarray:
        """Agent positions (voxel indices), shape (N, 3)."""
        return np.asarray(self._s.agents(), dtype=float).reshape(-1, 3)

    # history
    def undo(self) -> bool:
        """Undo the last action; False when there was nothing to undo."""
        return self._s.undo()

    def redo(self) -> bool:
        return self._s.redo()

    @property
    def can_undo(self) -> bool:
        return self._s.can_undo()

    @property
    def can_redo(self) -> bool:
        return self._s.can_redo()

    # level set in and out
    def load_mask(self, mask) -> None:
        """Start from a mask (non-zero inside; clears the history)."""
        self._s.load_mask(np.asarray(mask.array if isinstance(mask, Image) else mask))

    def load_phi(self, phi) -> None:
        """Start from a level-set function (< 0 inside; clears the history)."""
        self._s.load_phi(np.asarray(phi.array if isinstance(phi, Image) else phi))

    def mask(self) -> Image:
        """φ < 0 within the ROI, uint8 0/1."""
        return self.image.like(self._s.mask())

    def phi(self) -> Image:
        return self.image.like(self._s.phi())


def _warned(status: dict) -> dict:
    """Issues a run's warnings (a leak out of the brain) as Python warnings too."""
    for w in status["warnings"]:
        warnings.warn(w, UserWarning, stacklevel=3)
    return status


def _edit_range(decision: str, edit_range: Optional[float]) -> float:
    """The brush: as given, else 3 voxels for a cut and none (0) for the other rules."""
    if edit_range is not None:
        return float(edit_range)
    return 3.0 if decision == "cut" else 0.0


def repair(phi_or_mask, image, targets: Sequence[Sequence[float]], *, steps: int = 300, roi=None,
           agents: int = 200, p: float = 0.1, seed: int = 1, decision: str = "intensity",
           edit_range: Optional[float] = None) -> Image:
    """Agent-swarm repair (paper §4) of a segmentation at the given targets (voxel indices), one
    after the other, `steps` swarm steps each; returns the repaired φ (< 0 inside). ``image`` is
    the intensity image the swarm's decisions read. ``decision``: ``"intensity"`` (population
    statistics), ``"random"`` (the paper's speed test) or ``"cut"`` (cut a handle of the
    segmentation at the target: only removals that cut a handle are kept; brush ``edit_range``, 3
    voxels by default), as ``liveset repair --decision``. Uses Session (exact step, not the CLI's
    ``liveset repair`` option set: no @STEP schedule, no log)."""
    img = as_image(image)
    s = Session(img, roi="none" if roi is None else roi, agents=agents, p=p, seed=seed, decision=decision, edit_range=edit_range,
                bias_correct=False)  # the image as given, as `liveset repair --image`
    src = as_image(phi_or_mask, "phi_or_mask")
    a = np.asarray(src.array)
    if np.all((a == 0) | (a == 1)):
        s.load_mask(a)
    else:
        s.load_phi(a)
    for t in targets:
        s.set_target(t)
        s.swarm(steps)
    return s.phi()


def repair_holes(phi_or_mask, image, holes: int = 10, *, roi=None, sheet_band=None, min_voxels: int = 50,
                 round_steps: int = 1000, agents: int = 200, p: float = 0.3, seed: int = 1,
                 between_share: float = 0.25):
    """``liveset repair --find-holes``: no clicks — the truth-free finder's ``holes`` largest holes
    (>= ``min_voxels``, 12 voxels apart) are repaired one round each with the sheet rule (brush sized
    to the hole, the sheet's band sampled around it), as ``liveset demo --brain --repair`` does.
    ``image``: the image the segmentation came from (the bias-corrected one if it was segmented
    with bias correction); ``sheet_band=(lower, upper)`` raw, by default the tissue model's band of
    the sheet's class. ``between_share``: the smallest share of the sheet's tissue, by intensity
    (partial-volume model), that a voxel out of the band must hold to be added for lying between the
    sheet's sides (0.5: the band only; 0: up to the neighbouring tissues' means; the CLI's
    ``--between-share``). Returns ``(phi, report)``: the repaired φ (< 0 inside) and ``{"targets",
    "verdicts", "closed", "voxels_added", "finder": {"before", "after", ...}, ...}`` as the CLI's
    ``--json``. Unlike segment, it does not stop on Ctrl-C (holes × round_steps swarm steps, about
    a second per 1 000 on a brain)."""
    img = as_image(image)
    src = as_image(phi_or_mask, "phi_or_mask")
    if not src.same_geometry(img):
        raise ValueError("phi_or_mask and the image do not share a geometry (shape, spacing, origin or direction)")
    a = np.asarray(src.array)
    is_mask = bool(np.all((a == 0) | (a == 1)))
    r = _mask_arg(roi, img, "roi")
    r = None if r is None else r != 0
    if int(holes) < 1 or int(round_steps) < 1 or int(min_voxels) < 1 or int(agents) < 1:
        raise ValueError("holes, round_steps, min_voxels and agents must be at least 1")
    if not 0.0 <= float(between_share) <= 0.5:
        raise ValueError(f"between_share must be in [0, 0.5], got {between_share}")
    band = None if sheet_band is None else (float(sheet_band[0]), float(sheet_band[1]))
    level = (a != 0) if is_mask else np.asarray(a, dtype=np.float32)
    phi, report = _liveset._repair_holes(level, is_mask, np.asarray(img.array, dtype=np.float32), r, img.geometry, band,
                                          int(holes), int(min_voxels), int(round_steps), int(agents), float(p), int(seed),
                                          float(between_share), bool(img.oriented))
    return img.like(phi), json.loads(report)
