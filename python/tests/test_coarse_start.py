"""The coarse start (``coarse_start``, as ``liveset segment --coarse-start``): off by default on the
phantom's 1 mm grid, on when asked, with its steps reported first through ``progress`` (level
"coarse") and the same mask as the CLI's, bit for bit; a bad value, or "on" with an initial mask,
is a ValueError."""
import nibabel as nib
import numpy as np
import pytest

import liveset
from conftest import cli


def test_coarse_start_as_the_cli_runs_it(phantom, tmp_path):
    img = liveset.read(phantom["image"])
    plain = liveset.segment(img, phantom["seeds"])
    assert plain.report["coarse_start"] is None  # a 1 mm grid: auto leaves it off
    levels = []
    coarse = liveset.segment(img, phantom["seeds"], coarse_start="on", progress=lambda p: levels.append(p["level"]))
    c = coarse.report["coarse_start"]
    assert c["used"] and c["dims"] == [(d + 1) // 2 for d in img.shape] and c["spacing"][0] == 2.0
    assert levels == ["coarse"] * c["iterations"] + ["fine"] * coarse.report["iterations"]
    a, b = plain.mask.array > 0, coarse.mask.array > 0
    assert 2 * (a & b).sum() / (a.sum() + b.sum()) > 0.97
    out = tmp_path / "coarse.nii.gz"
    args = ["segment", phantom["image"]]
    for s in phantom["seeds"]:
        args += ["--seed", s]
    cli(*args, "--coarse-start", "on", "-q", "--out-mask", str(out))
    assert np.array_equal(np.asarray(nib.load(str(out)).dataobj) > 0, b)
    with pytest.raises(ValueError, match="coarse_start"):
        liveset.segment(img, phantom["seeds"], coarse_start="yes")
    with pytest.raises(ValueError, match="init_mask"):  # as the CLI's --coarse-start on --init-mask
        liveset.segment(img, phantom["seeds"], init_mask=plain.mask, coarse_start="on")
