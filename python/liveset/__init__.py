"""liveset: real-time interactive level-set segmentation of 3D MR images, from Python.

Images are numpy arrays with their geometry (``liveset.Image``: spacing, origin, direction in LPS
like ITK; ``Image.from_nibabel`` / ``to_nibabel`` convert nibabel's RAS affines).

    import nibabel as nib, liveset
    img = liveset.Image.from_nibabel(nib.load("t1.nii.gz"))
    seg = liveset.segment(img, seeds=[(35, 83, 113)], roi="auto")
    nib.save(seg.mask.to_nibabel(), "seg.nii.gz")
    surf = liveset.mesh(seg.phi)                 # vertices/faces in LPS mm
    print(liveset.evaluate(seg.mask, truth, label=2)["dice"])

Functions: read, read_header, write, segment, tissue_model, mesh, evaluate, find_holes, repair, repair_holes, set_threads; classes
Image, Session, Segmentation, Mesh; exception ImageIOError (an OSError). Other bad input raises
ValueError with a one-line message. Long calls release the GIL and stop on Ctrl-C.
Cohorts: ``liveset.batch`` (``python3 -m liveset.batch MANIFEST.csv --out DIR``) on Dask.
"""
from . import _liveset
from .api import (ImageIOError, Mesh, Segmentation, evaluate, find_holes, mesh, read, read_header, segment,
                  set_threads, tissue_model, write)
from .image import Image
from .session import Session, repair, repair_holes

__version__ = _liveset.__version__
__all__ = ["Image", "ImageIOError", "Mesh", "Segmentation", "Session", "evaluate", "find_holes", "mesh", "read",
           "read_header", "repair", "repair_holes", "segment", "set_threads", "tissue_model", "write"]
