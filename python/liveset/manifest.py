"""The cohort manifest of ``liveset batch``: a CSV with a header, one subject per row, checked
completely before any work starts (one clear line naming the row on the first problem)."""
from __future__ import annotations

import csv
import hashlib
import json
import os
import re
from dataclasses import dataclass, field

REQUIRED = ("subject", "image", "seeds")
# Optional columns: files, the evaluation, and `liveset segment`'s options (empty cell: default).
FILES = ("roi", "truth", "init_mask")
FLOATS = ("mu", "epsilon", "mu_raw", "epsilon_raw", "n", "alpha", "smooth_mm", "seed_radius")
INTS = {"label": (0, 255), "classes": (2, 6), "iterations": (1, 10_000_000)}
CHOICES = {"window_from": ("model", "seeds"), "coarse_start": ("auto", "on", "off")}
BOOLS = ("bias_correct", "thin_fronts")
DEFAULTS_EPOCH = 78  # see Subject.fingerprint
KNOWN = set(REQUIRED) | set(FILES) | set(FLOATS) | set(INTS) | set(CHOICES) | set(BOOLS) | {"seeds_mm"}
_SUBJECT = re.compile(r"^[A-Za-z0-9][A-Za-z0-9._+-]*$")


class ManifestError(ValueError):
    """A bad manifest: the message is one line naming the file and the row."""


@dataclass
class Subject:
    """One row: its id, absolute paths, parsed seeds and segment options."""
    subject: str
    row: int                      # line number in the CSV (the header is line 1)
    image: str
    seeds: list                   # ["I,J,K[:R]", ...] as the CLI's --seed
    seeds_mm: list = field(default_factory=list)
    roi: str | None = None        # a file, "auto", "none" or None (the default: auto on a head)
    truth: str | None = None
    label: int | None = None
    init_mask: str | None = None
    options: dict = field(default_factory=dict)  # mu, epsilon, ..., as liveset.segment's keywords

    def fingerprint(self) -> str:
        """Changes when anything that affects the outputs changes (inputs' paths, sizes, times, options)."""
        files = [p for p in (self.image, self.roi, self.truth, self.init_mask) if p and p not in ("auto", "none")]
        stats = [(p, os.stat(p).st_size, os.stat(p).st_mtime_ns) for p in files]
        # DEFAULTS_EPOCH: bumped when a default that changes the outputs changes (session 48: N4 by
        # default; 49: the curvature per mm, which changes every scan not at 1 mm; 50: α chosen from
        # the image unless given; 54: noisy scans pre-smoothed unless α is given; 56: the automatic
        # brain mask raised above noisy air (55) and found again after N4; 57: the tissue model fitted
        # through noise that hides a tissue, the brain looked for within 170 mm of the head's top; 58: the
        # mask after N4 looked for in the head found before it; 59: the automatic brain mask the
        # default ROI of a head, and a defaced head no longer taken for a stripped brain; 60: N4 fitted
        # above the floor of an image with negative values, the head's top found from the head where
        # the header gives no orientation, and the neck cut only where a neck leaves the image; 61: a
        # stripped brain's mid-range outside; 65: a tilted head's brain extracted below the 170 mm cut
        # where it meets it, and the tissue model's brain looked for as the header says; 66: a T2's or
        # PD's contrast read by the deep head's two peaks, its model fitted above white matter, and the
        # mask found again after N4 kept only where it reads the head as the first did; 67: the bright
        # CSF about a T2's or PD's brain taken into its automatic mask, a ROI file read for its
        # contrast, and a grey-brighter reading before N4 kept; 69: a tissue class seen mostly mixed
        # kept, a ROI file that is a whole brain read as one; 70: the brain mask's last look, white
        # matter's peak swamped by large ventricles; 72: the thin-front rule on by default; 78: the
        # coarse start on grids of voxels at most 0.85 mm), so a resumed cohort recomputes what older
        # defaults made.
        blob = json.dumps([self.image, self.seeds, self.seeds_mm, self.roi, self.truth, self.label,
                           self.init_mask, sorted(self.options.items()), stats, DEFAULTS_EPOCH], default=str)
        return hashlib.sha256(blob.encode()).hexdigest()[:16]


def parse_seeds(text: str, where: str) -> list:
    """ "I,J,K;I,J,K:R" -> ["I,J,K", "I,J,K:R"], each three finite numbers and an optional radius > 0."""
    seeds = [s.strip() for s in text.split(";") if s.strip()]
    if not seeds:
        raise ManifestError(f"{where}: no seeds (expected I,J,K;I,J,K with optional :R radii)")
    for s in seeds:
        coords, _, radius = s.partition(":")
        parts = coords.split(",")
        try:
            values = [float(p) for p in parts] + ([float(radius)] if radius else [])
        except ValueError:
            values = None
        if values is None or len(parts) != 3 or not all(v == v and abs(v) != float("inf") for v in values) \
                or (radius and values[3] <= 0):
            raise ManifestError(f"{where}: bad seed '{s}' (expected I,J,K or I,J,K:R, e.g. 35,83,113)")
    return seeds


def _path(value: str, base: str, where: str, column: str) -> str:
    p = value if os.path.isabs(value) else os.path.normpath(os.path.join(base, value))
    if not os.path.exists(p):
        raise ManifestError(f"{where}: {column} '{value}' does not exist")
    if not os.access(p, os.R_OK) or (os.path.isdir(p) and not os.access(p, os.X_OK)):
        raise ManifestError(f"{where}: {column} '{value}' is not readable")
    return p


def _option(column: str, value: str, where: str):
    try:
        if column in FLOATS:
            v = float(value)
            if v != v or abs(v) == float("inf"):
                raise ValueError
            return v
        if column in INTS:
            v = int(value)
            lo, hi = INTS[column]
            if not lo <= v <= hi:
                raise ManifestError(f"{where}: {column} {v} outside {lo}..{hi}")
            return v
    except ValueError:
        raise ManifestError(f"{where}: {column} '{value}' is not a {'number' if column in FLOATS else 'whole number'}") from None
    if column in CHOICES:
        if value not in CHOICES[column]:
            raise ManifestError(f"{where}: {column} '{value}' is not one of {', '.join(CHOICES[column])}")
        return value
    if column in BOOLS:
        v = value.lower()
        if v not in ("1", "0", "true", "false", "yes", "no"):
            raise ManifestError(f"{where}: {column} '{value}' is not true/false")
        return v in ("1", "true", "yes")
    raise AssertionError(column)


def _subject(row: dict, line: int, base: str, where: str) -> Subject:
    name = row["subject"]
    if not _SUBJECT.match(name):
        raise ManifestError(f"{where}: subject '{name}' is not a usable folder name "
                            "(letters, digits, . _ + -; not starting with . or -)")
    if not row["image"]:
        raise ManifestError(f"{where}: no image")
    s = Subject(subject=name, row=line, image=_path(row["image"], base, where, "image"),
                seeds=parse_seeds(row["seeds"], where) if row["seeds"] or not row.get("seeds_mm") else [])
    if row.get("seeds_mm"):
        s.seeds_mm = parse_seeds(row["seeds_mm"], where)
    for column in FILES:
        value = row.get(column) or ""
        if value in ("auto", "none") and column == "roi":
            s.roi = value
        elif value:
            setattr(s, column, _path(value, base, where, column))
    for column, value in row.items():
        if value and column in KNOWN and column not in REQUIRED and column not in FILES and column != "seeds_mm":
            v = _option(column, value, where)
            if column == "label":
                s.label = v
            else:
                s.options[column] = v
    if s.label is not None and not s.truth:
        raise ManifestError(f"{where}: label needs a truth")
    if ("mu" in s.options) + ("mu_raw" in s.options) > 1 or ("epsilon" in s.options) + ("epsilon_raw" in s.options) > 1:
        raise ManifestError(f"{where}: give mu or mu_raw (epsilon or epsilon_raw), not both")
    if "smooth_mm" in s.options and "alpha" not in s.options:
        raise ManifestError(f"{where}: smooth_mm needs alpha (the automatic choice sets both)")
    return s


def read_manifest(path: str, check_images: bool = True) -> list[Subject]:
    """Parse and check the whole manifest; ManifestError (one line) on the first problem. With
    check_images, also each image's header and that its voxel seeds lie inside it."""
    try:
        with open(path, newline="", encoding="utf-8-sig") as f:
            text = f.read()
    except OSError as e:
        raise ManifestError(f"cannot read manifest '{path}': {e.strerror or e}") from None
    except UnicodeDecodeError:
        raise ManifestError(f"manifest '{path}' is not UTF-8 text") from None
    reader = csv.reader(text.splitlines())
    header = next(reader, None)
    if not header:
        raise ManifestError(f"manifest '{path}' is empty (expected a header: subject,image,seeds,...)")
    header = [h.strip() for h in header]
    missing = [c for c in REQUIRED if c not in header]
    if missing:
        raise ManifestError(f"manifest '{path}': missing column(s) {', '.join(missing)} "
                            f"(header: {','.join(header)})")
    unknown = [c for c in header if c not in KNOWN]
    if unknown:
        raise ManifestError(f"manifest '{path}': unknown column(s) {', '.join(unknown)} "
                            f"(known: {', '.join(sorted(KNOWN))})")
    if len(set(header)) != len(header):
        raise ManifestError(f"manifest '{path}': a column name repeats in the header")
    base = os.path.dirname(os.path.abspath(path))
    subjects, seen = [], {}
    for line, cells in enumerate(reader, start=2):
        if not any(c.strip() for c in cells):
            continue
        where = f"manifest '{path}' row {line}"
        if len(cells) != len(header):
            raise ManifestError(f"{where}: {len(cells)} cells, the header has {len(header)}")
        row = {h: c.strip() for h, c in zip(header, cells)}
        s = _subject(row, line, base, where)
        if s.subject in seen:
            raise ManifestError(f"{where}: subject '{s.subject}' repeats row {seen[s.subject]}")
        seen[s.subject] = line
        subjects.append(s)
    if not subjects:
        raise ManifestError(f"manifest '{path}' lists no subjects")
    if check_images:
        for s in subjects:
            _check_image(s, f"manifest '{path}' row {s.row}")
    return subjects


def _check_image(s: Subject, where: str) -> None:
    """The image's header is readable and every voxel seed lies inside it (as `liveset segment`
    checks, but before any work)."""
    import liveset
    try:
        h = liveset.read_header(s.image)
    except OSError as e:
        raise ManifestError(f"{where}: image: {e}") from None
    dims = h["dims"]
    for seed in s.seeds:
        c = [float(v) for v in seed.partition(":")[0].split(",")]
        if not all(0 <= c[a] <= dims[a] - 1 for a in range(3)):
            raise ManifestError(f"{where}: seed {seed} lies outside the image ({dims[0]}x{dims[1]}x{dims[2]} voxels)")
