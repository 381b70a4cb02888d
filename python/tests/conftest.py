"""Fixtures of the Python suite: the `liveset` CLI built alongside (LIVESET_CLI, set by ctest),
small phantoms written by `liveset phantom`, and their CLI segmentations as references."""
import json
import os
import subprocess
import sys

import pytest

HERE = os.path.dirname(os.path.abspath(__file__))
CLI = os.environ.get("LIVESET_CLI", os.path.join(HERE, "..", "..", "build", "liveset"))
if not os.environ.get("PYTHONPATH"):  # run by hand: the build's package
    sys.path.insert(0, os.path.join(HERE, "..", "..", "build", "python"))

PHANTOM_SIZE = 48


def cli(*args, check=True, **kw):
    """Run the liveset CLI; returns the CompletedProcess (text)."""
    r = subprocess.run([CLI, *map(str, args)], capture_output=True, text=True, **kw)
    if check and r.returncode != 0:
        raise AssertionError(f"liveset {' '.join(map(str, args))} failed ({r.returncode}): {r.stderr}")
    return r


def make_phantom(out_dir, seed=1, size=PHANTOM_SIZE):
    """A phantom folder (t1.nii.gz, truth_gm.nii.gz, ...) and its phantom.json."""
    cli("phantom", "--out", out_dir, "--size", size, "--seed", seed, "--quiet")
    with open(os.path.join(out_dir, "phantom.json")) as f:
        return json.load(f)


def seed_args(info):
    return [f"{s[0]},{s[1]},{s[2]}" for s in info["seeds"]]


@pytest.fixture(scope="session")
def phantom(tmp_path_factory):
    d = tmp_path_factory.mktemp("phantom")
    info = make_phantom(str(d))
    return {"dir": str(d), "image": str(d / "t1.nii.gz"), "truth": str(d / "truth_gm.nii.gz"),
            "seeds": seed_args(info), "info": info}


@pytest.fixture(scope="session")
def cli_segmentation(phantom, tmp_path_factory):
    """`liveset segment` of the phantom from its seeds: mask, phi and the JSON report."""
    d = tmp_path_factory.mktemp("cli_seg")
    args = ["segment", phantom["image"]]
    for s in phantom["seeds"]:
        args += ["--seed", s]
    r = cli(*args, "--out-mask", d / "mask.nii.gz", "--out-phi", d / "phi.nii.gz", "--json")
    return {"mask": str(d / "mask.nii.gz"), "phi": str(d / "phi.nii.gz"), "report": json.loads(r.stdout)}
