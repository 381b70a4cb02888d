"""The Python API against independent answers: nibabel for geometry, the CLI for segment/eval,
numpy brute force for overlap, an analytic sphere for mesh positions."""
import json
import warnings
import os
import signal
import threading

import nibabel as nib
import numpy as np
import pytest

import liveset
from conftest import cli

# An oblique, anisotropic geometry (LPS): rotation about z by 30 degrees, then about x by 20.
_C, _S = np.cos(np.radians(30)), np.sin(np.radians(30))
_CX, _SX = np.cos(np.radians(20)), np.sin(np.radians(20))
DIRECTION = np.array([[1, 0, 0], [0, _CX, -_SX], [0, _SX, _CX]]) @ np.array([[_C, -_S, 0], [_S, _C, 0], [0, 0, 1]])
SPACING = (0.9, 1.1, 1.7)
ORIGIN = (12.5, -40.0, 7.25)


def ras_affine(spacing, origin, direction):
    """Expected nibabel affine, written out independently of liveset.Image."""
    a = np.eye(4)
    a[:3, :3] = direction @ np.diag(spacing)
    a[:3, 3] = origin
    a[0, :] *= -1
    a[1, :] *= -1
    return a


def test_write_then_nibabel_reads_same_voxels_and_geometry(tmp_path):
    rng = np.random.default_rng(3)
    data = rng.normal(100, 20, size=(7, 9, 5)).astype(np.float32)
    img = liveset.Image(data, SPACING, ORIGIN, DIRECTION)
    liveset.write(img, tmp_path / "x.nii.gz")
    back = nib.load(str(tmp_path / "x.nii.gz"))
    np.testing.assert_allclose(back.affine, ras_affine(SPACING, ORIGIN, DIRECTION), atol=1e-4)
    assert np.array_equal(np.asarray(back.dataobj), data)
    # a label image stays integer, non-zero -> 1 for masks
    liveset.write(img.like(data > 100), tmp_path / "m.nii.gz", labels=True)
    m = nib.load(str(tmp_path / "m.nii.gz"))
    assert m.get_data_dtype() == np.uint8 and np.array_equal(np.asarray(m.dataobj), (data > 100).astype(np.uint8))


def test_nibabel_file_read_by_liveset_and_back(tmp_path):
    data = np.arange(6 * 4 * 3, dtype=np.int16).reshape(6, 4, 3)
    affine = ras_affine(SPACING, ORIGIN, DIRECTION)
    nib.save(nib.Nifti1Image(data, affine), str(tmp_path / "n.nii.gz"))
    img = liveset.read(tmp_path / "n.nii.gz")
    assert img.array.shape == (6, 4, 3) and img.array.dtype == np.float32
    assert np.array_equal(img.array, data.astype(np.float32))
    np.testing.assert_allclose(img.spacing, SPACING, atol=1e-5)
    np.testing.assert_allclose(img.origin, ORIGIN, atol=1e-4)
    np.testing.assert_allclose(img.direction, DIRECTION, atol=1e-5)
    # zero copy out: a Fortran-ordered view on the C++ grid
    assert img.array.flags.f_contiguous and not img.array.flags.owndata
    # nibabel interop in memory: Image <-> Nifti1Image keeps the affine
    via = liveset.Image.from_nibabel(nib.load(str(tmp_path / "n.nii.gz")))
    np.testing.assert_allclose(via.affine, affine, atol=1e-5)
    np.testing.assert_allclose(via.to_nibabel().affine, affine, atol=1e-5)


def test_freesurfer_mgz_read_and_written_as_nibabel_places_it(tmp_path):
    """FreeSurfer's .mgz/.mgh (liveset's own reader and writer, Debian's ITK has none) against
    nibabel's: every voxel type nibabel writes, an oblique affine, compressed or not; liveset's
    files read by nibabel with the same voxels and affine; `liveset segment` takes one and writes
    its mask as one."""
    rng = np.random.default_rng(5)
    data = rng.normal(100, 20, size=(9, 7, 6))
    affine = ras_affine(SPACING, ORIGIN, DIRECTION)
    for dtype in (np.uint8, np.int16, np.int32, np.float32):
        for ext in ("mgz", "mgh"):
            f = str(tmp_path / f"n_{np.dtype(dtype).name}.{ext}")
            nib.save(nib.MGHImage(data.astype(dtype), affine), f)
            img = liveset.read(f)
            assert np.array_equal(img.array, np.asarray(nib.load(f).dataobj).astype(np.float32)), f
            np.testing.assert_allclose(img.affine, nib.load(f).affine, atol=1e-4, err_msg=f)
            assert img.oriented and liveset.read_header(f)["format"] == "MGH"
    img = liveset.Image(data.astype(np.float32), SPACING, ORIGIN, DIRECTION)
    for ext in ("mgz", "mgh"):
        liveset.write(img, tmp_path / f"l.{ext}")
        liveset.write(img.like(data > 100), tmp_path / f"m.{ext}", labels=True)
        back, mask = nib.load(str(tmp_path / f"l.{ext}")), nib.load(str(tmp_path / f"m.{ext}"))
        np.testing.assert_allclose(back.affine, affine, atol=1e-4)
        assert np.array_equal(np.asarray(back.dataobj), img.array)
        assert mask.get_data_dtype() == np.uint8 and np.array_equal(np.asarray(mask.dataobj), (data > 100).astype(np.uint8))
    head = _bridged_head()
    nib.save(nib.MGHImage(head.array, head.affine), str(tmp_path / "head.mgz"))
    cli("segment", tmp_path / "head.mgz", "--seed", "32,32,32:3", "--mu-raw", 130, "--epsilon-raw", 40, "--iterations", 20,
        "--no-bias-correct", "--out-mask", tmp_path / "seg.mgz", "--quiet")
    seg = nib.load(str(tmp_path / "seg.mgz"))
    np.testing.assert_allclose(seg.affine, head.affine, atol=1e-4)
    ref = liveset.segment(head, [(32, 32, 32, 3)], mu_raw=130, epsilon_raw=40, iterations=20, bias_correct=False)
    assert np.array_equal(np.asarray(seg.dataobj), ref.mask.array)


def test_segment_equals_cli_bitwise(phantom, cli_segmentation):
    img = liveset.Image.from_nibabel(nib.load(phantom["image"]))
    seg = liveset.segment(img, phantom["seeds"])
    cli_mask = np.asarray(nib.load(cli_segmentation["mask"]).dataobj)
    cli_phi = np.asarray(nib.load(cli_segmentation["phi"]).dataobj)
    assert seg.mask.array.dtype == np.uint8 and np.array_equal(seg.mask.array, cli_mask)
    assert np.array_equal(seg.phi.array.view(np.uint32), cli_phi.astype(np.float32).view(np.uint32))
    rep = cli_segmentation["report"]
    for k in ("iterations", "stop", "voxels", "mu_raw", "epsilon_raw", "alpha", "alpha_choice"):
        assert seg.report[k] == rep[k], k
    assert rep["alpha_choice"]["source"] == "automatic"
    # where the seconds went: consecutive phases making up the total (no read nor write: arrays in memory)
    ps = seg.report["phase_seconds"]
    assert set(ps) == {"roi", "bias_correction", "segmentation", "total"}
    assert all(v >= 0 for v in ps.values())
    assert ps["roi"] + ps["bias_correction"] + ps["segmentation"] == pytest.approx(ps["total"], abs=1e-6)
    assert ps["segmentation"] >= seg.report["seconds"]
    assert set(rep["phase_seconds"]) == {"read", "roi", "bias_correction", "segmentation", "write", "total"}
    # masks/phi go out with the input's affine
    np.testing.assert_allclose(seg.mask.to_nibabel().affine, nib.load(phantom["image"]).affine, atol=1e-6)
    # the tissue model gives the window segment used
    tm = liveset.tissue_model(img, phantom["seeds"])
    assert tm["window"]["mu_raw"] == pytest.approx(rep["mu_raw"], abs=1e-9)
    assert tm["window"]["source"] == rep["window"]["source"]
    means = [c["mean"] for c in tm["tissue_model"]["classes"]]
    assert means == sorted(means)


def test_bias_correction_is_the_default_and_false_turns_it_off(phantom, cli_segmentation):
    """N4 first by default (as ``liveset segment``, whose report the fixture holds), off with
    bias_correct=False; the default skips it with a warning where N4 cannot run (a ROI between its
    grid's samples), where bias_correct=True refuses with a ValueError. An image shifted below zero
    (an offset) is fitted above its floor: the unshifted one's voxels, to within N4 fitted on the
    air's own value."""
    img = liveset.Image.from_nibabel(nib.load(phantom["image"]))
    on = liveset.segment(img, phantom["seeds"], iterations=20)
    off = liveset.segment(img, phantom["seeds"], iterations=20, bias_correct=False)
    assert "bias_correction" in on.report and on.corrected is not None
    assert on.report["bias_correction"]["field_min"] == pytest.approx(cli_segmentation["report"]["bias_correction"]["field_min"], abs=0)
    assert "bias_correction" not in off.report and off.corrected is None
    assert liveset.tissue_model(img, phantom["seeds"])["bias_correction"]["mask"] == on.report["bias_correction"]["mask"]
    shifted = liveset.Image.from_nibabel(nib.Nifti1Image(np.asarray(nib.load(phantom["image"]).dataobj, dtype=np.float32) - 5000.0,
                                                         nib.load(phantom["image"]).affine))
    offset = liveset.segment(shifted, phantom["seeds"], iterations=20)
    assert -5000.0 <= offset.report["bias_correction"]["offset"] < -4990.0
    a, b = offset.mask.array != 0, on.mask.array != 0  # to within N4 on the air's own value (1.3)
    assert 2 * (a & b).sum() / (a.sum() + b.sum()) > 0.995
    block = np.zeros(img.shape, np.uint8)
    block[1:5, 1:5, 1:5] = 1
    skipped = liveset.segment(img, [(2, 2, 2, 1)], roi=img.like(block), iterations=20)
    assert "bias_correction" not in skipped.report
    assert any("the uncorrected image is used" in w for w in skipped.report["warnings"]), skipped.report["warnings"]
    with pytest.raises(ValueError, match="bias correction|no voxel"):
        liveset.segment(img, [(2, 2, 2, 1)], roi=img.like(block), iterations=20, bias_correct=True)


def test_evaluate_matches_brute_force_and_cli(phantom, cli_segmentation):
    mask, truth = liveset.read(cli_segmentation["mask"], labels=True), liveset.read(phantom["truth"], labels=True)
    ev = liveset.evaluate(mask, truth)
    m, t = mask.array != 0, truth.array != 0
    assert ev["dice"] == pytest.approx(2 * np.sum(m & t) / (m.sum() + t.sum()), rel=1e-12)
    assert ev["jaccard"] == pytest.approx(np.sum(m & t) / np.sum(m | t), rel=1e-12)
    ref = json.loads(cli("eval", "--mask", cli_segmentation["mask"], "--truth", phantom["truth"], "--json").stdout)
    for k in ("dice", "hausdorff95_mm", "genus", "components"):
        assert ev[k] == ref[k], k


def test_evaluate_takes_several_labels_as_one_structure():
    """FreeSurfer's aseg names the cortex 3 and 42: evaluate(label=(3, 42)) scores a mask of both
    as 1, label=3 alone 2/3 (brute force), as ``liveset eval --label 3,42``."""
    t = np.zeros((20, 20, 20), np.uint8)
    t[5:15, 5:15, 5:10], t[5:15, 5:15, 10:15], t[1, 1, 1] = 3, 42, 2
    m = np.zeros_like(t)
    m[5:15, 5:15, 5:15] = 1
    truth, mask = liveset.Image(t, (1, 1, 1), (0, 0, 0), np.eye(3)), liveset.Image(m, (1, 1, 1), (0, 0, 0), np.eye(3))
    assert liveset.evaluate(mask, truth, label=(3, 42))["dice"] == pytest.approx(1.0)
    assert liveset.evaluate(mask, truth, label=[3, 42])["dice"] == pytest.approx(1.0)
    assert liveset.evaluate(mask, truth, label=3)["dice"] == pytest.approx(2 / 3)
    with pytest.raises(ValueError, match="no voxel with label 7,8"):
        liveset.evaluate(mask, truth, label=(7, 8))


def test_mesh_of_analytic_sphere_lies_on_it_in_lps_mm(tmp_path):
    shape, centre, radius = (30, 26, 18), np.array([20.0, -5.0, 14.0]), 8.0
    img = liveset.Image(np.zeros(shape, np.float32), SPACING, ORIGIN, DIRECTION)
    ijk = np.stack(np.meshgrid(*[np.arange(n) for n in shape], indexing="ij"), -1).reshape(-1, 3)
    world = (img.affine_lps @ np.c_[ijk, np.ones(len(ijk))].T).T[:, :3]
    centre = world.mean(axis=0)
    phi = (np.linalg.norm(world - centre, axis=1) - radius).reshape(shape, order="C").astype(np.float32)
    m = liveset.mesh(img.like(phi), out=tmp_path / "s.ply")
    d = np.linalg.norm(m.vertices - centre, axis=1)
    assert len(m.faces) > 100 and np.max(np.abs(d - radius)) < 0.05 * radius
    outward = np.einsum("ij,ij->i", m.normals, m.vertices - centre)
    assert np.all(outward > 0)
    assert os.path.getsize(tmp_path / "s.ply") > 0


def test_bad_input_raises_one_line_errors(tmp_path, phantom):
    with pytest.raises(liveset.ImageIOError, match="no-such.nii.gz") as e:
        liveset.read(tmp_path / "no-such.nii.gz")
    assert isinstance(e.value, OSError) and "\n" not in str(e.value)
    (tmp_path / "bad.nii.gz").write_bytes(b"\x1f\x8b not really gzip")
    with pytest.raises(liveset.ImageIOError):
        liveset.read(tmp_path / "bad.nii.gz")
    img = liveset.read(phantom["image"])
    with pytest.raises(ValueError, match="lies outside the image"):
        liveset.segment(img, [(500, 1, 1)])
    with pytest.raises(ValueError, match="not both"):
        liveset.segment(img, phantom["seeds"], mu=0.5, mu_raw=100)
    with pytest.raises(ValueError, match="bad seed|seed"):
        liveset.segment(img, ["1,2"])
    with pytest.raises(ValueError, match="at least one seed"):
        liveset.segment(img, [])
    with pytest.raises(ValueError, match="roi"):
        liveset.segment(img, phantom["seeds"], roi=np.ones((3, 3, 3)))
    with pytest.raises(ValueError, match="3D"):
        liveset.Image(np.zeros((4, 4)))
    with pytest.raises(ValueError, match="NaN"):
        liveset.segment(img.like(np.full(img.shape, np.nan, np.float32)), phantom["seeds"])
    with pytest.raises(ValueError, match="geometry"):
        liveset.evaluate(img.like(img.array > 0), liveset.Image(img.array > 0, (2, 2, 2)))
    with pytest.raises(liveset.ImageIOError, match="does not exist"):
        liveset.write(img, tmp_path / "missing-folder" / "x.nii.gz")


def test_sigint_stops_a_segmentation_within_a_step(phantom):
    """A real SIGINT to this process while segment runs with the GIL released: KeyboardInterrupt,
    and no further step is taken after the signal arrived."""
    img = liveset.read(phantom["image"])
    steps, zero = [], []

    def progress(p):
        if zero:  # the first steps evaluate the whole zero layer they start from (nothing sleeps yet)
            assert p["awake"] == zero[-1]
        steps.append(p["iteration"])
        zero.append(p["zero_layer"])
        if p["iteration"] == 3:
            os.kill(os.getpid(), signal.SIGINT)

    with pytest.raises(KeyboardInterrupt):
        liveset.segment(img, phantom["seeds"], progress=progress, iterations=100000)
    assert steps == [1, 2, 3]


def test_sigint_while_the_gil_is_released_stops_a_long_segmentation():
    """SIGINT from another thread while segment runs in C++ without a callback: the run stops
    (KeyboardInterrupt) long before the front could have crossed the 160^3 image."""
    rng = np.random.default_rng(1)
    img = liveset.Image(rng.uniform(0, 1, size=(160, 160, 160)).astype(np.float32))
    timer = threading.Timer(0.3, signal.pthread_kill, (threading.main_thread().ident, signal.SIGINT))
    timer.start()
    try:
        with pytest.raises(KeyboardInterrupt):
            liveset.segment(img, [(2, 2, 2)], mu=0.5, epsilon=0.7, alpha=0.0, iterations=100000)
    finally:
        timer.cancel()


def test_gil_released_during_segment(phantom):
    img = liveset.read(phantom["image"])
    done, ticks = threading.Event(), []
    t = threading.Thread(target=lambda: (liveset.segment(img, phantom["seeds"], iterations=400), done.set()))
    t.start()
    while not done.is_set():  # this loop only runs while the C++ side has let go of the GIL
        ticks.append(1)
        done.wait(0.001)
    t.join()
    assert len(ticks) > 5


def test_session_steps_undo_redo_and_swarm(phantom):
    img = liveset.read(phantom["image"])
    s = liveset.Session(img, bias_correct=False)  # keep the bias field's weak spots
    assert not s.corrected and s.image is img
    seeds = [tuple(map(float, x.split(","))) for x in phantom["seeds"]]
    for seed in seeds:
        s.add_seed(seed)
    assert len(s.seeds) == len(seeds)
    before = s.mask().array.copy()
    st = s.run(300)
    assert st["steps"] > 0 and s.status["iterations"] == st["steps"]
    grown = s.mask().array.copy()
    assert grown.sum() > before.sum()
    assert s.undo() and np.array_equal(s.mask().array, before)
    assert s.redo() and np.array_equal(s.mask().array, grown)
    s.set_target(phantom["info"]["weak_spots"][0])  # a hole the phantom's bias field opens
    s.swarm(60)
    assert s.agents.shape[1] == 3 and len(s.agents) > 0
    repaired = s.mask().array.copy()
    assert not np.array_equal(repaired, grown)  # the swarm edited the surface there
    assert s.undo() and np.array_equal(s.mask().array, grown)
    # repair() is the same swarm run on a loaded level set
    phi = liveset.repair(liveset.Image(grown, img.spacing, img.origin, img.direction), img,
                         [phantom["info"]["weak_spots"][0]], steps=60)
    assert phi.array.shape == img.shape and np.sum((phi.array < 0) != (grown != 0)) > 0
    with pytest.raises(ValueError, match="outside"):
        s.add_seed((1e4, 0, 0))


def test_session_chooses_alpha_as_segment_does(phantom):
    # A noisy phantom on 1 x 1 x 1.5 mm voxels, where the automatic alpha is neither 0 nor 0.1.
    src = liveset.read(phantom["image"])
    noisy = src.array + np.random.default_rng(5).normal(0, 0.12 * float(np.ptp(src.array)), src.shape)
    img = liveset.Image(noisy.astype(np.float32), (1.0, 1.0, 1.5), src.origin, src.direction)
    seeds = [tuple(map(float, x.split(","))) for x in phantom["seeds"]]
    seg = liveset.segment(img, seeds, bias_correct=False)
    assert seg.report["alpha_choice"]["source"] == "automatic" and 0 < seg.report["alpha"] < 0.1
    s = liveset.Session(img, bias_correct=False)
    for seed in seeds:
        s.add_seed(seed)
    assert s.params["alpha_automatic"] and s.params["alpha"] == seg.report["alpha"]
    # Noisy: the automatic choice blurs the image the threshold term reads, in both alike.
    assert seg.report["smooth_mm"] == 0.5 and s.params["smooth_mm"] == seg.report["smooth_mm"]
    s.run(2000)
    assert np.array_equal(s.mask().array, seg.mask.array)
    s.set_params(alpha=0.2)  # a given alpha drops the automatic blur, as segment(alpha=0.2)
    assert not s.params["alpha_automatic"] and s.params["alpha"] == 0.2 and s.params["smooth_mm"] == 0.0
    s.set_params(smooth_mm=0.7)
    s.set_params(alpha=0.25)  # fixed to fixed: the blur stays
    assert s.params["smooth_mm"] == 0.7 and s.params["alpha"] == 0.25
    s.set_params(alpha="auto")
    assert s.params["alpha_automatic"] and s.params["alpha"] == seg.report["alpha"] and s.params["smooth_mm"] == 0.5
    assert liveset.Session(img, alpha=0.1, bias_correct=False).params["alpha"] == 0.1
    assert liveset.Session(img, alpha=0.1, bias_correct=False).params["smooth_mm"] == 0.0
    with pytest.raises(ValueError, match="auto"):
        s.set_params(alpha="automatic")
    with pytest.raises(ValueError, match="smooth_mm needs"):
        s.set_params(smooth_mm=1.0)  # automatic alpha: the choice sets both
    with pytest.raises(ValueError, match="smooth_mm needs alpha"):
        liveset.Session(img, smooth_mm=1.0, bias_correct=False)
    with pytest.raises(ValueError, match="smooth_mm needs alpha"):
        liveset.segment(img, seeds, smooth_mm=1.0, bias_correct=False)
    # Given with alpha: the same mask as the session with the same alpha and smoothing.
    fixed = liveset.segment(img, seeds, alpha=0.05, smooth_mm=0.8, bias_correct=False)
    assert fixed.report["smooth_mm"] == 0.8 and fixed.report["alpha_choice"]["source"] == "given"
    t = liveset.Session(img, alpha=0.05, smooth_mm=0.8, bias_correct=False)
    for seed in seeds:
        t.add_seed(seed)
    t.run(2000)
    assert np.array_equal(t.mask().array, fixed.mask.array)
    unblurred = liveset.segment(img, seeds, alpha=0.05, bias_correct=False)
    assert unblurred.report["smooth_mm"] == 0 and not np.array_equal(unblurred.mask.array, fixed.mask.array)


def test_session_prepares_the_image_as_segment_does(phantom):
    # By default both run N4 (fitted in the brain mask found before it) and fit the tissue model
    # in that mask: the same seeds give the same mask, voxel for voxel.
    img = liveset.read(phantom["image"])
    seeds = [tuple(map(float, x.split(","))) for x in phantom["seeds"]]
    seg = liveset.segment(img, seeds)
    assert "bias_correction" in seg.report and seg.corrected is not None
    s = liveset.Session(img)
    assert s.corrected and np.array_equal(s.image.array, seg.corrected.array)
    untimed = lambda r: {k: v for k, v in r["bias_correction"].items() if not k.endswith("ms")}
    assert untimed(s.report) == untimed(seg.report) and untimed(s.report)["mask"] == "auto brain mask"
    for seed in seeds:
        s.add_seed(seed)
    assert s.params["alpha"] == seg.report["alpha"]
    s.run(2000)
    assert s.status["converged"]
    assert int(seg.mask.array.sum()) > 1000 and np.array_equal(s.mask().array, seg.mask.array)
    # roi="auto": segment's automatic brain mask, N4 fitted in it
    seg = liveset.segment(img, seeds, roi="auto")
    s = liveset.Session(img, roi="auto")
    assert np.array_equal(s.roi.array, seg.roi.array) and s.report["roi"]["source"] == "auto"
    assert np.array_equal(s.image.array, seg.corrected.array)
    for seed in seeds:
        s.add_seed(seed)
    s.run(2000)
    assert np.array_equal(s.mask().array, seg.mask.array)
    with pytest.raises(ValueError, match="does not overlay|shape"):
        liveset.Session(img, roi=np.ones((3, 3, 3), np.uint8))
    with pytest.raises(ValueError, match="auto"):
        liveset.Session(img, roi="brain")


def _bridged_head():
    """An analytic head (WM, GM, CSF, skull, scalp) with a bridge of WM intensity to the scalp."""
    g = np.indices((64, 64, 64)).astype(float)
    r = 1.5 * np.sqrt(((g - 31.5) ** 2).sum(axis=0))
    a = np.select([r < 18, r < 27, r < 29, r < 35, r < 42], [130.0, 95.0, 45.0, 8.0, 160.0], 0.0)
    a = np.abs(a + np.random.default_rng(5).normal(0, 3, a.shape))
    bridge = np.zeros(a.shape, bool)
    bridge[40:, 29:35, 29:35] = True
    a[bridge & (r < 42)] = 130.0
    return liveset.Image(a.astype(np.float32), (1.5, 1.5, 1.5))


def test_segment_warns_when_a_front_without_roi_leaks_out_of_the_brain():
    img = _bridged_head()
    kw = dict(mu_raw=130, epsilon_raw=40, iterations=400, bias_correct=False)
    leaked = liveset.segment(img, [(32, 32, 32, 3)], roi="none", **kw)
    warned = [w for w in leaked.report["warnings"] if "outside the automatic brain mask" in w]
    assert len(warned) == 1 and "roi='auto'" in warned[0] and "roi" not in leaked.report
    inside = liveset.segment(img, [(32, 32, 32, 3)], roi="auto", **kw)
    assert not any("outside the automatic brain mask" in w for w in inside.report["warnings"])
    assert int(inside.mask.array.sum()) < int(leaked.mask.array.sum())
    # The default on a full head is the automatic brain mask: roi="auto"'s voxels, marked as the default.
    by_default = liveset.segment(img, [(32, 32, 32, 3)], **kw)
    assert np.array_equal(by_default.mask.array, inside.mask.array)
    assert by_default.report["roi"]["default"] and not inside.report["roi"]["default"]
    assert np.array_equal(by_default.roi.array, inside.roi.array)
    # A seed in the air beside one in the brain is left out (named); alone, it asks for something else
    # than the brain: the default ROI is dropped, with a warning, and the run is roi="none"'s.
    both = liveset.segment(img, [(32, 32, 32, 3), (2, 2, 2)], **kw)
    assert np.array_equal(both.mask.array, inside.mask.array)
    assert any("the seed at voxel (2, 2, 2) lies outside" in w and "roi='none'" in w for w in both.report["warnings"])
    air = dict(mu_raw=8, epsilon_raw=6, iterations=50, bias_correct=False)
    alone = liveset.segment(img, [(2, 2, 2)], **air)
    assert np.array_equal(alone.mask.array, liveset.segment(img, [(2, 2, 2)], roi="none", **air).mask.array)
    assert "roi" not in alone.report and alone.roi is None
    assert any("every seed lies outside" in w for w in alone.report["warnings"])
    with pytest.raises(ValueError, match="every seed lies outside the automatic brain mask"):
        liveset.segment(img, [(2, 2, 2)], roi="auto", **air)


def test_a_head_where_no_brain_is_found_is_warned_about_by_default(tmp_path):
    """The cortex phantom under 20 % noise: a head is found, but its brain mask is a fragment ("no
    brain found"); by default the whole image is segmented, as roi="none", with a report warning
    naming roi; roi="auto" is a ValueError; roi="none" says nothing of it (as the CLI,
    RoiAutoCli.AHeadWhereNoBrainIsFoundIsSaidNotSilentlySegmentedWhole)."""
    cli("phantom", "--out", tmp_path, "--size", 64, "--noise", 0.2, "--quiet")
    img = liveset.read(str(tmp_path / "t1.nii.gz"))
    kw = dict(mu_raw=900, epsilon_raw=300, iterations=20, bias_correct=False)
    said = "the default ROI: a head was found but no brain in it"
    by_default = liveset.segment(img, [(32, 32, 32)], **kw)
    warned = [w for w in by_default.report["warnings"] if said in w]
    assert len(warned) == 1 and "give roi a brain mask" in warned[0], by_default.report["warnings"]
    assert "roi" not in by_default.report and by_default.roi is None
    none = liveset.segment(img, [(32, 32, 32)], roi="none", **kw)
    assert not any(said in w for w in none.report["warnings"])
    assert np.array_equal(by_default.mask.array, none.mask.array)
    with pytest.raises(ValueError, match="no brain found"):
        liveset.segment(img, [(32, 32, 32)], roi="auto", **kw)
    session = liveset.Session(img, bias_correct=False)
    assert any(said in w for w in session.report["warnings"]), session.report


def test_a_file_without_orientation_reaches_the_brain_mask_as_such(tmp_path):
    """A NIfTI with neither qform nor sform (as an Analyze file) is read as not oriented, by
    liveset.read and from nibabel, and segment, tissue_model and Session find the head's top from
    the head (the report's roi.auto.superior), as ``liveset segment`` does; a copy keeps the flag."""
    img = _bridged_head()
    plain, unoriented = str(tmp_path / "oriented.nii.gz"), str(tmp_path / "unoriented.nii.gz")
    liveset.write(img, plain)
    n = nib.Nifti1Image(img.array, None)
    n.header.set_qform(None, code=0)
    n.header.set_sform(None, code=0)
    nib.save(n, unoriented)
    assert liveset.read(plain).oriented and liveset.read_header(plain)["oriented"]
    u = liveset.read(unoriented)
    assert not u.oriented and not liveset.read_header(unoriented)["oriented"]
    assert not liveset.Image.from_nibabel(nib.load(unoriented)).oriented
    assert liveset.Image.from_nibabel(nib.load(plain)).oriented
    analyze = str(tmp_path / "unoriented.img")
    nib.save(nib.AnalyzeImage(img.array, np.eye(4)), analyze)
    assert not liveset.Image.from_nibabel(nib.load(analyze)).oriented and not liveset.read(analyze).oriented
    # Headers without qform/sform (MINC's, PAR/REC's, the base class's; `in` fails on them) are oriented.
    assert liveset.Image.from_nibabel(nib.spatialimages.SpatialImage(img.array, np.eye(4))).oriented
    minc = str(tmp_path / "oriented.mnc")
    liveset.write(img, minc)
    assert liveset.read(minc).oriented
    try:
        import h5py  # noqa: F401  (nibabel reads MINC 2 through it)
    except ImportError:
        pass
    else:
        assert liveset.Image.from_nibabel(nib.load(minc)).oriented
    assert not u.like(u.array).oriented and not liveset.read(unoriented, labels=False).oriented
    kw = dict(mu_raw=130, epsilon_raw=40, iterations=5, bias_correct=False)
    for image, superior in ((liveset.read(plain), "header"), (u, "from the head")):
        assert liveset.segment(image, [(32, 32, 32, 3)], roi="auto", **kw).report["roi"]["auto"]["superior"] == superior
        s = liveset.Session(image, roi="auto", bias_correct=False)
        assert s.report["roi"]["auto"]["superior"] == superior


def test_outputs_of_a_file_without_orientation_are_placed_by_nibabel_where_it_places_the_file(tmp_path):
    """nibabel places a NIfTI without qform and sform by pixdim (x flipped); an output written with
    the identity LPS axes and codes 1 would lie mirrored in y against it. So the outputs of such a
    file (liveset.write of the image or of a segmentation's mask, `liveset segment`'s mask, φ, ROI
    and corrected image) have codes 0 and nibabel's affine of the file; an oriented file's outputs
    keep its affine with codes set."""
    img = _bridged_head()
    n = nib.Nifti1Image(img.array, None)
    n.header.set_zooms((1.5, 1.5, 1.5))
    n.header.set_qform(None, code=0)
    n.header.set_sform(None, code=0)
    src = str(tmp_path / "unoriented.nii.gz")
    nib.save(n, src)
    source = nib.load(src)
    u = liveset.read(src)
    seg = liveset.segment(u, [(32, 32, 32, 3)], mu_raw=130, epsilon_raw=40, iterations=5, bias_correct=False)
    outputs = {"image": (u, False), "mask": (seg.mask, True)}
    for name, (image, labels) in outputs.items():
        liveset.write(image, str(tmp_path / f"{name}.nii.gz"), labels=labels)
    cli("segment", src, "--seed", "32,32,32:3", "--mu-raw", 130, "--epsilon-raw", 40, "--iterations", 5, "--roi", "auto",
        "--out-mask", tmp_path / "cli_mask.nii", "--out-phi", tmp_path / "cli_phi.nii.gz", "--out-roi", tmp_path / "cli_roi.nii.gz",
        "--out-corrected", tmp_path / "cli_corrected.nii.gz", "--quiet")
    written = list(outputs) + ["cli_mask", "cli_phi", "cli_roi", "cli_corrected"]
    for name in written:
        f = nib.load(str(tmp_path / (name + (".nii" if name == "cli_mask" else ".nii.gz"))))
        assert int(f.header["qform_code"]) == 0 and int(f.header["sform_code"]) == 0, name
        np.testing.assert_allclose(f.affine, source.affine, atol=1e-5, err_msg=name)
        assert f.shape == source.shape, name
    np.testing.assert_array_equal(np.asarray(nib.load(str(tmp_path / "mask.nii.gz")).dataobj), seg.mask.array)
    oriented = liveset.read(str(tmp_path / "image.nii.gz"))
    assert not oriented.oriented and int(source.header["sform_code"]) == 0
    liveset.write(liveset.Image(u.array, u.spacing, u.origin, u.direction), str(tmp_path / "oriented.nii.gz"))
    f = nib.load(str(tmp_path / "oriented.nii.gz"))
    assert int(f.header["sform_code"]) != 0
    np.testing.assert_allclose(f.affine, np.diag([-1.5, -1.5, 1.5, 1.0]), atol=1e-5)  # the LPS identity in RAS


def test_session_warns_as_segment_when_its_front_leaks_out_of_the_brain():
    img = _bridged_head()
    seg = liveset.segment(img, [(32, 32, 32, 3)], roi="none", mu_raw=130, epsilon_raw=40, iterations=1000, bias_correct=False)
    expected = [w for w in seg.report["warnings"] if "outside the automatic brain mask" in w]
    assert len(expected) == 1
    for roi in ("none", "auto", None):
        s = liveset.Session(img, roi=roi, bias_correct=False)
        s.add_seed((32, 32, 32), 3)
        p = s.params  # the window segment was given, in the session's normalised units
        per_raw = p["epsilon"] / p["epsilon_raw"]
        s.set_params(mu=p["mu"] + (130 - p["mu_raw"]) * per_raw, epsilon=40 * per_raw, alpha=seg.report["alpha"],
                     smooth_mm=seg.report["smooth_mm"])
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            status = s.run(1000)
        assert status["converged"]
        if roi == "none":  # the same front as segment's, the same warning, also as a Python warning
            assert np.array_equal(s.mask().array, seg.mask.array)
            assert status["warnings"] == expected and [str(w.message) for w in caught] == expected
        else:  # "auto", and the default on a full head
            assert status["warnings"] == [] and not caught
            assert int(s.mask().array.sum()) < int(seg.mask.array.sum())
            assert s.report["roi"]["default"] == (roi is None)
    s = liveset.Session(img, bias_correct=False)
    with pytest.raises(ValueError, match="outside the region of interest.*roi='none'"):
        s.add_seed((2, 2, 2))


def test_docs_example_runs(tmp_path):
    """docs/python_example.py end to end on a small phantom."""
    import subprocess
    import sys
    script = os.path.join(os.path.dirname(__file__), "..", "..", "docs", "python_example.py")
    r = subprocess.run([sys.executable, script, "--size", "48", "--out", str(tmp_path)], capture_output=True, text=True)
    assert r.returncode == 0, r.stderr
    result = json.loads(r.stdout.strip().splitlines()[-1])
    assert result["dice"] > 0.8 and result["triangles"] > 0
    seg = nib.load(str(tmp_path / "seg.nii.gz"))
    np.testing.assert_allclose(seg.affine, nib.load(str(tmp_path / "t1.nii.gz")).affine, atol=1e-6)


def _centred_grid(n):
    """The voxel indices of an n^3 grid (n, n, n, 3), their distance from its centre, and the centre."""
    c = (n - 1) / 2
    ijk = np.stack(np.meshgrid(*[np.arange(n)] * 3, indexing="ij"), -1).astype(float)
    return ijk, np.linalg.norm(ijk - c, axis=-1), c


def test_find_holes_finds_exactly_a_drilled_hole():
    # A grey-matter shell (0.5) between white matter (1.0) and CSF (0.1), segmented except for a
    # 4x4 shaft drilled through the top: the finder's one candidate is exactly the drilled voxels.
    ijk, r, c = _centred_grid(40)
    image = np.where(r < 8, 1.0, np.where(r < 12, 0.5, 0.1)).astype(np.float32)
    shell = (r >= 8) & (r < 12)
    drilled = shell & (np.abs(ijk[..., 0] - c) < 2) & (np.abs(ijk[..., 1] - c) < 2) & (ijk[..., 2] > c)
    img = liveset.Image(image, SPACING, ORIGIN, DIRECTION)
    found = liveset.find_holes(img.like((shell & ~drilled).astype(np.uint8)), img, sheet_band=(0.3, 0.75), min_voxels=1)
    assert found["band_from"] == "user"
    assert len(found["holes"]) == 1
    hole = found["holes"][0]
    assert hole["voxels"] == int(drilled.sum())
    assert drilled[tuple(hole["target"])]
    intact = liveset.find_holes(img.like(shell.astype(np.uint8)), img, sheet_band=(0.3, 0.75), min_voxels=1)
    assert intact["holes"] == []
    with pytest.raises(ValueError):
        liveset.find_holes(img.like(shell.astype(np.uint8)), img, sheet_band=(0.75, 0.3))


def test_repair_holes_closes_the_finders_holes_inside_the_shell():
    # The same shell with two shafts drilled through it (GM-bright): repair_holes (the CLI's
    # --find-holes) aims at the finder's sites, fills the shafts and adds nothing outside the shell.
    ijk, r, c = _centred_grid(48)
    image = np.where(r < 12, 130.0, np.where(r < 16, 100.0, 50.0)).astype(np.float32)
    shell = (r >= 12) & (r < 16)
    shafts = shell & (((np.hypot(ijk[..., 0] - c, ijk[..., 1] - c) <= 2.5) & (ijk[..., 2] > c)) |
                      ((np.hypot(ijk[..., 1] - c, ijk[..., 2] - c) <= 2.0) & (ijk[..., 0] < c)))
    img = liveset.Image(image, SPACING, ORIGIN, DIRECTION)
    seg = img.like((shell & ~shafts).astype(np.uint8))
    found = liveset.find_holes(seg, img, sheet_band=(75, 115), min_voxels=10)
    phi, report = liveset.repair_holes(seg, img, 2, sheet_band=(75, 115), min_voxels=10, round_steps=400)
    assert [t for t in report["targets"]] == [h["target"] for h in found["holes"][:2]]
    assert report["closed"] == 2 and report["finder"]["after"] == 0
    after = phi.array < 0
    assert phi.same_geometry(img)
    assert after[shafts].mean() >= 0.9
    assert not (after & ~shell & ~(seg.array != 0)).any()
    with pytest.raises(ValueError):
        liveset.repair_holes(seg, img, 0)
    with pytest.raises(ValueError):
        liveset.repair_holes(seg, img, 2, sheet_band=(75, 115), between_share=0.7)


def test_repair_cut_removes_a_handle_and_nothing_else():
    # A shell whose mask took in a one-voxel rod of the core's tissue across the core (a handle):
    # repair(decision="cut") at the rod's middle removes rod voxels only, and the rod no longer
    # joins the shell's two sides (its voxels are not all there); elsewhere nothing moves.
    ijk, r, c = _centred_grid(33)
    image = np.where(r <= 9, 130.0, np.where(r <= 12, 100.0, 50.0)).astype(np.float32)
    rod = (r <= 9) & (ijk[..., 1] == c) & (ijk[..., 2] == c)
    mask = ((r > 9) & (r <= 12)) | rod
    img = liveset.Image(image, SPACING, ORIGIN, DIRECTION)
    phi = liveset.repair(img.like(mask.astype(np.uint8)), img, [(c, c, c)], steps=100, p=0.3, decision="cut")
    after = phi.array < 0
    removed = mask & ~after
    assert removed.any()
    assert not (removed & ~rod).any()
    assert not (after & ~mask).any()
    with pytest.raises(ValueError):
        liveset.repair(img.like(mask.astype(np.uint8)), img, [(c, c, c)], decision="maybe")
    with pytest.raises(ValueError):
        liveset.repair(img.like(mask.astype(np.uint8)), img, [(c, c, c)], decision="cut", edit_range=0)


def test_noise_that_hides_a_tissue_is_seen_through_the_blur_as_segment_sees_it():
    # BrainWeb under Rician noise σ 18 with roi="auto" (a whole brain) and without a ROI: segment,
    # tissue_model and the Session all fit the tissue model on the blurred image (grey and white
    # matter overlap on the image itself) and choose the same window, α and blur.
    here = os.path.dirname(os.path.abspath(__file__))
    t1 = liveset.read(os.path.join(here, "..", "..", "data", "brainweb", "t1.mha"))
    rng = np.random.default_rng(57)
    a = t1.array.astype(np.float64)
    img = t1.like(np.hypot(a + rng.normal(0, 18, a.shape), rng.normal(0, 18, a.shape)).astype(np.float32))
    seed = (35, 83, 113)
    seg = liveset.segment(img, [seed], roi="auto", iterations=1)
    tm = seg.report["tissue_model"]
    assert len(tm["classes"]) == 3 and tm["fitted_smooth_mm"] == 0.5 and seg.report["smooth_mm"] == 0.5
    assert any("noise hid a tissue" in w for w in seg.report["warnings"])
    model = liveset.tissue_model(img, [seed], roi="auto")
    assert model["tissue_model"]["fitted_smooth_mm"] == 0.5 and model["window"]["mu"] == seg.report["mu"]
    s = liveset.Session(img, roi="auto")
    s.add_seed(seed)
    p = s.params
    assert (p["mu"], p["epsilon"], p["alpha"], p["smooth_mm"]) == (seg.report["mu"], seg.report["epsilon"], seg.report["alpha"], 0.5)
    # without a ROI the automatic brain mask is the fit region: the same again
    seg = liveset.segment(img, [seed], iterations=1, roi="none")
    assert seg.report["tissue_model"]["fitted_smooth_mm"] == 0.5
    s = liveset.Session(img, roi="none")
    s.add_seed(seed)
    p = s.params
    assert (p["mu"], p["epsilon"], p["alpha"], p["smooth_mm"]) == (seg.report["mu"], seg.report["epsilon"], seg.report["alpha"], 0.5)


def test_a_nan_masked_brain_is_read_as_nibabel_reads_it_and_segmented_as_its_lowered_outside(tmp_path):
    # SPM's masked images hold NaN outside the brain: liveset.read keeps NaN where nibabel reads
    # it; segment, tissue_model and Session read those voxels as lying below the rest, exactly as
    # the same brain with its outside lowered by hand (and as `liveset segment` on the file).
    a = _bridged_head().array
    r = 1.5 * np.sqrt(((np.indices(a.shape) - 31.5) ** 2).sum(axis=0))
    a[r >= 29] = np.nan
    path = str(tmp_path / "nan_brain.nii.gz")
    nib.save(nib.Nifti1Image(a, np.diag([1.5, 1.5, 1.5, 1])), path)
    img = liveset.read(path)
    assert np.array_equal(np.isnan(img.array), np.isnan(np.asarray(nib.load(path).dataobj)))
    assert np.array_equal(img.array[r < 29], a[r < 29])
    low = a.copy()
    lo, hi = np.nanmin(a), np.nanmax(a)
    low[np.isnan(a)] = np.float32(lo) - np.float32(0.01) * (np.float32(hi) - np.float32(lo))
    kw = dict(iterations=150, bias_correct=False)
    seg, ref = liveset.segment(img, [(49, 32, 32, 2)], **kw), liveset.segment(img.like(low), [(49, 32, 32, 2)], **kw)
    assert seg.report["no_data_voxels"] == int(np.isnan(a).sum()) and ref.report["no_data_voxels"] == 0
    assert np.array_equal(seg.mask.array, ref.mask.array) and seg.mask.array.sum() > 5000
    assert not seg.mask.array[np.isnan(a)].any()
    n4 = liveset.segment(img, [(49, 32, 32, 2)], iterations=5)
    assert np.array_equal(np.isnan(n4.corrected.array), np.isnan(a))  # NaN again where the image had it
    out = str(tmp_path / "mask.nii.gz")
    cli("segment", path, "--seed", "49,32,32:2", "--iterations", "150", "--no-bias-correct", "--quiet", "--out-mask", out)
    assert np.array_equal(np.asarray(nib.load(out).dataobj), seg.mask.array)
    assert liveset.tissue_model(img, [(49, 32, 32, 2)], bias_correct=False)["window"] == \
        liveset.tissue_model(img.like(low), [(49, 32, 32, 2)], bias_correct=False)["window"]
    s = liveset.Session(img, bias_correct=False)
    assert not s.corrected and not np.isnan(s.image.array).any() and s.report["no_data_voxels"] == int(np.isnan(a).sum())
    lifted = img.like(img.array + 100.0)  # no offset for N4 to take off: it divides the lowered voxels by its field too
    s = liveset.Session(lifted, bias_correct=True)
    assert s.corrected and s.image.array[np.isnan(a)].max() < s.image.array[~np.isnan(a)].min()
    written = str(tmp_path / "written.nii.gz")
    liveset.write(img, written)  # NaN written as read
    assert np.array_equal(np.isnan(np.asarray(nib.load(written).dataobj)), np.isnan(a))


def test_nan_is_found_in_every_chunk_of_a_big_endian_float64_nifti_and_masks_refuse_it(tmp_path):
    # 7 MB of float64 (liveset reads a NIfTI's data 1 MiB at a time): NaN where nibabel has it, in
    # the first chunk, later ones and the last voxel; a mask array holding NaN is refused.
    a = np.random.default_rng(3).normal(100, 10, (96, 96, 96))
    a.flat[[5, 200000, 500001, a.size - 1]] = np.nan
    img = nib.Nifti1Image(a, np.eye(4), nib.Nifti1Header(endianness=">"))
    img.set_data_dtype(np.float64)
    path = str(tmp_path / "big_endian_f8.nii.gz")
    nib.save(img, path)
    assert nib.load(path).header.endianness == ">" and nib.load(path).get_data_dtype() == np.dtype(">f8")
    got = liveset.read(path).array
    assert np.array_equal(np.isnan(got), np.isnan(a))
    small = liveset.Image(np.nan_to_num(a[:32, :32, :32], nan=100.0).astype(np.float32))
    roi = np.ones((32, 32, 32))
    roi[0, 0, 0] = np.nan
    with pytest.raises(ValueError, match="mask holds NaN"):
        liveset.segment(small, [(16, 16, 16)], roi=roi, mu_raw=100, epsilon_raw=20, iterations=2, bias_correct=False)
