"""The thin-front rule, on by default since session 72 in ``liveset.segment`` and ``Session`` as in
``liveset segment``: the front fills a sheet one voxel thick joined to a seeded cube, as the CLI does,
bit for bit; with ``thin_fronts=False`` (``--no-thin-fronts``) it stops early."""
import inspect

import nibabel as nib
import numpy as np

import liveset
from conftest import cli


def _sheet():
    x, y, z = np.meshgrid(np.arange(64), np.arange(24), np.arange(24), indexing="ij")
    cube = (x >= 2) & (x < 9) & (y >= 4) & (y < 20) & (z >= 8) & (z < 15)
    sheet = cube | ((x >= 8) & (x < 60) & (y >= 4) & (y < 20) & (z == 12))
    ripple = ((7 * x + 13 * y + 29 * z) % 5 - 2).astype(np.float32)  # ±2, as scripts/thin_structures.sh's noise
    return sheet, np.where(sheet, 100.0, 0.0).astype(np.float32) + ripple


def test_thin_fronts_fill_a_sheet_one_voxel_thick_as_the_cli_does(tmp_path):
    sheet, image = _sheet()
    opts = dict(roi="none", mu_raw=100, epsilon_raw=30, alpha=0, bias_correct=False)
    without = liveset.segment((image, np.eye(4)), [(5, 11, 11)], thin_fronts=False, **opts).mask.array > 0
    thin = liveset.segment((image, np.eye(4)), [(5, 11, 11)], **opts).mask.array > 0  # the default
    assert not (thin & ~sheet).any() and not (without & ~sheet).any()
    assert np.array_equal(thin, sheet)
    assert np.nonzero(without.any(axis=(1, 2)))[0].max() < 20  # the front stops early without the rule
    path = tmp_path / "sheet.nii.gz"
    nib.save(nib.Nifti1Image(image, np.eye(4)), str(path))
    # The CLI's default (no flag) is the Python default, both from the C++ segment_step().
    for flag, want in (("--thin-fronts", thin), ("--no-thin-fronts", without), ("-q", thin)):
        out = tmp_path / ("out%s.nii.gz" % flag)
        cli("segment", str(path), "--seed", "5,11,11", "--roi", "none", "--mu-raw", "100", "--epsilon-raw", "30",
            "--alpha", "0", "--no-bias-correct", flag, "-q", "--out-mask", str(out))
        assert np.array_equal(np.asarray(nib.load(str(out)).dataobj) > 0, want), flag
    assert liveset._liveset.DEFAULT_THIN_FRONTS is True
    for f in (liveset.segment, liveset.Session):
        assert inspect.signature(f).parameters["thin_fronts"].default is liveset._liveset.DEFAULT_THIN_FRONTS


def test_a_session_gives_segments_mask_with_the_rule_on_by_default():
    sheet, image = _sheet()
    seg = liveset.segment((image, np.eye(4)), [(5, 11, 11)], roi="none", mu_raw=100, epsilon_raw=30, alpha=0,
                          bias_correct=False)
    s = liveset.Session((image, np.eye(4)), roi="none", alpha=0, bias_correct=False)  # the rule on by default
    s.set_params(mu=seg.report["mu"], epsilon=seg.report["epsilon"])  # the same window, normalised
    s.add_seed((5, 11, 11))
    s.run(2000)
    assert np.array_equal(s.mask().array > 0, sheet)
    assert np.array_equal(s.mask().array, seg.mask.array)


def test_a_manifest_column_turns_thin_fronts_off_for_its_subject(tmp_path):
    from liveset.manifest import read_manifest
    m = tmp_path / "cohort.csv"
    for name in ("a", "b"):
        (tmp_path / f"{name}.nii.gz").write_bytes(b"")  # not read: check_images=False
    m.write_text('subject,image,seeds,thin_fronts\na,a.nii.gz,"1,2,3",false\nb,b.nii.gz,"1,2,3",\n')
    a, b = read_manifest(str(m), check_images=False)
    assert a.options["thin_fronts"] is False and "thin_fronts" not in b.options  # empty: the default (on)
