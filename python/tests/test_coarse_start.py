"""The coarse start (``coarse_start``, as ``liveset segment --coarse-start``): off by default on the
phantom's 1 mm grid, on when asked, with its steps reported first through ``progress`` (level
"coarse") and the same mask as the CLI's, bit for bit; a bad value, or "on" with an initial mask,
is a ValueError; a Session starts coarse as segment does."""
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


def test_a_session_starts_coarse_as_segment_does(phantom):
    """The Session's coarse start (the viewer's): its first steps are the coarse run's iterations,
    then the image's grid refines, and the mask is segment's with the same coarse_start, bit for bit."""
    img = liveset.read(phantom["image"])
    seeds = [tuple(map(float, x.split(","))) for x in phantom["seeds"]]
    seg = liveset.segment(img, seeds, coarse_start="on", bias_correct=False)
    c = seg.report["coarse_start"]
    s = liveset.Session(img, bias_correct=False, coarse_start="on")
    for seed in seeds:
        s.add_seed(seed)
    seeds_only = s.mask().array.copy()
    st = s.step(3)
    assert st["coarse"] and st["coarse_iterations"] == 3 and st["iterations"] == 0
    assert np.array_equal(s.mask().array, seeds_only)  # the coarse iterations leave the image's grid alone
    st = s.run(seg.report["iterations"] + 1)  # counts the image's grid's steps only
    assert st["converged"] and not st["coarse"]
    assert st["coarse_iterations"] == c["iterations"] and st["iterations"] == seg.report["iterations"]
    assert np.array_equal(s.mask().array, seg.mask.array)
    # Off: the image's grid from the seeds, as segment's coarse_start="off".
    t = liveset.Session(img, bias_correct=False, coarse_start="off")
    t.add_seed(seeds[0])
    assert not t.step()["coarse"] and t.status["iterations"] == 1
    with pytest.raises(ValueError, match="coarse_start"):
        liveset.Session(img, coarse_start="yes")
