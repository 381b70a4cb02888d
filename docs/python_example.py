#!/usr/bin/python3
"""liveset from Python: load a T1 with nibabel, segment grey matter from seeds, mesh it, evaluate
it against a truth, and save the mask with the input's affine.

    PYTHONPATH=build/python /usr/bin/python3 docs/python_example.py            # a 96^3 phantom
    PYTHONPATH=build/python /usr/bin/python3 docs/python_example.py --brain    # BrainWeb (~1-2 min)
"""
import argparse
import json
import os
import subprocess
import tempfile

import nibabel as nib

import liveset

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)


def inputs(args, work):
    """(image path, truth path, truth label, roi, seeds)"""
    if args.brain:
        d = os.path.join(ROOT, "data", "brainweb")
        seeds = ["35,83,113", "35,125,38", "44,164,92", "71,74,53", "122,149,47", "140,86,74", "38,71,26", "83,23,71"]
        roi = liveset.Image.from_nibabel(nib.load(os.path.join(d, "brain_mask.nii.gz")))
        return os.path.join(d, "t1.mha"), os.path.join(d, "labels_crisp.nii.gz"), 2, roi, seeds
    cli = os.environ.get("LIVESET_CLI", os.path.join(ROOT, "build", "liveset"))
    subprocess.run([cli, "phantom", "--out", work, "--size", str(args.size), "--quiet"], check=True)
    with open(os.path.join(work, "phantom.json")) as f:
        seeds = [tuple(s) for s in json.load(f)["seeds"]]  # (i, j, k) voxel indices
    return os.path.join(work, "t1.nii.gz"), os.path.join(work, "truth_gm.nii.gz"), None, None, seeds


def main():
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--brain", action="store_true", help="BrainWeb T1 with its brain mask and labels")
    p.add_argument("--size", type=int, default=96, help="phantom size (without --brain)")
    p.add_argument("--out", default=None, help="folder for seg.nii.gz and surface.ply (default: a temporary one)")
    args = p.parse_args()
    work = args.out or tempfile.mkdtemp(prefix="liveset-example-")
    os.makedirs(work, exist_ok=True)
    image_path, truth_path, label, roi, seeds = inputs(args, work)

    # 1. load: nibabel for NIfTI (RAS affine), liveset.read for anything ITK reads (here .mha)
    image = liveset.read(image_path) if image_path.endswith(".mha") else liveset.Image.from_nibabel(nib.load(image_path))
    print(f"image {image.shape}, spacing {image.spacing}")

    # 2. the tissue model and the window the seeds pick
    model = liveset.tissue_model(image, seeds, roi=roi)
    w = model["window"]
    print(f"window {w['lower_raw']:.1f}..{w['upper_raw']:.1f} ({w['source']}, class "
          f"{model['tissue_model']['seed_class']['name']})")

    # 3. segment (GIL released; Ctrl-C stops it), with a progress callback
    seg = liveset.segment(image, seeds, roi=roi,
                          progress=lambda s: print(f"\r  iteration {s['iteration']}", end="") if s["iteration"] % 50 == 0 else None)
    print(f"\nsegmented: {seg.report['iterations']} iterations, {seg.report['stop']}, "
          f"{seg.report['volume_mm3'] / 1000:.1f} ml")
    nib.save(seg.mask.to_nibabel(), os.path.join(work, "seg.nii.gz"))  # the input's affine

    # 4. mesh (LPS mm), written as PLY too
    surf = liveset.mesh(seg.phi, out=os.path.join(work, "surface.ply"))
    print(f"mesh: {len(surf.vertices)} vertices, {len(surf.faces)} triangles")

    # 5. evaluate against the truth
    truth = liveset.read(truth_path, labels=True)
    ev = liveset.evaluate(seg.mask, truth, label=label)
    print(f"Dice {ev['dice']:.4f}, HD95 {ev['hausdorff95_mm']:.2f} mm, genus {ev['genus']}")
    print(json.dumps({"dice": ev["dice"], "triangles": len(surf.faces), "out": work}))


if __name__ == "__main__":
    main()
