"""Cohort processing on Dask distributed: ``python3 -m liveset.batch MANIFEST.csv --out DIR
[--workers N | --scheduler ADDRESS]`` (also ``liveset batch ...``), or ``liveset.batch.run()``.

Each subject is segmented by a Dask task (liveset.segment, exactly as ``liveset segment``); its
outputs (mask.nii.gz, phi.nii.gz, report.json, with ``--mesh`` surface.ply) are written into a
hidden temporary folder and renamed to DIR/<subject>/ when complete. DIR/summary.csv gets one
row per subject. Finished subjects (report.json with the same inputs) are skipped on a re-run; a
subject that fails is recorded and the others go on (exit status 1); a worker that dies is
replaced and its subject re-run elsewhere (Dask's own rescheduling, plus ``--retries``).

The default cluster is a LocalCluster of N worker processes whose scheduler, workers, nannies and
HTTP endpoints listen on 127.0.0.1 only. ``--scheduler tcp://host:8786`` or ``tls://host:8786`` uses a running cluster
(workers must be able to import liveset and read the manifest's paths); TLS takes the
certificates from Dask's configuration (distributed.comm.tls.*) or --tls-ca-file/--tls-cert/--tls-key.
"""
from __future__ import annotations

import argparse
import csv
import glob
import io
import json
import logging
import os
import shutil
import sys
import time

from .manifest import ManifestError, Subject, read_manifest

SUMMARY_COLUMNS = ["subject", "status", "reused", "voxels", "volume_mm3", "dice", "iterations", "stop",
                   "seconds", "error"]


def _subject_dir(out: str, subject: str) -> str:
    return os.path.join(out, subject)


def finished(out: str, s: Subject, fingerprint: str):
    """The report of an earlier run of this subject with the same inputs, else None."""
    try:
        with open(os.path.join(_subject_dir(out, s.subject), "report.json"), encoding="utf-8") as f:
            report = json.load(f)
    except (OSError, ValueError):
        return None
    return report if report.get("status") == "ok" and report.get("fingerprint") == fingerprint else None


def process_subject(s: Subject, out: str, fingerprint: str, threads: int = 0, write_mesh: bool = False) -> dict:
    """Runs on a worker: segment one subject and publish DIR/<subject>/ atomically. Never raises
    for a bad subject: returns its summary row with status "failed" and the one-line error."""
    import liveset
    t0 = time.monotonic()
    tmp = os.path.join(out, f".{s.subject}.tmp-{os.getpid()}-{time.time_ns()}")
    row = {"subject": s.subject, "status": "failed", "reused": 0}
    try:
        os.makedirs(tmp)
        liveset.set_threads(threads)
        image = liveset.read(s.image)
        roi = s.roi if s.roi in (None, "auto", "none") else liveset.read(s.roi, labels=True)
        init = None if not s.init_mask else liveset.read(s.init_mask, labels=True)
        seg = liveset.segment(image, s.seeds, seeds_mm=s.seeds_mm, roi=roi, init_mask=init, **s.options)
        report = {"status": "ok", "subject": s.subject, "fingerprint": fingerprint, "image": s.image,
                  "seeds": s.seeds, "seeds_mm": s.seeds_mm, "roi": s.roi, "options": s.options,
                  "segmentation": seg.report, "outputs": {"mask": "mask.nii.gz", "phi": "phi.nii.gz"},
                  "worker": {"pid": os.getpid(), "host": os.uname().nodename}, "liveset": liveset.__version__}
        liveset.write(seg.mask, os.path.join(tmp, "mask.nii.gz"), labels=True)
        liveset.write(seg.phi, os.path.join(tmp, "phi.nii.gz"))
        if write_mesh:
            m = liveset.mesh(seg.phi, out=os.path.join(tmp, "surface.ply"), kind="phi")
            report["outputs"]["mesh"] = "surface.ply"
            report["mesh_triangles"] = int(len(m.faces))
        if s.truth:
            truth = liveset.read(s.truth, labels=True)
            report["evaluation"] = liveset.evaluate(seg.mask, truth, label=s.label)
            report["evaluation"]["label"] = s.label
        report["seconds"] = time.monotonic() - t0
        with open(os.path.join(tmp, "report.json"), "w", encoding="utf-8") as f:
            json.dump(report, f, indent=1)
            f.flush()
            os.fsync(f.fileno())
        _publish(tmp, _subject_dir(out, s.subject))
        return summary_row(report, reused=False)
    except Exception as e:  # one subject's failure is its row, not the run's
        row.update(error=" ".join(str(e).split()) or type(e).__name__, seconds=round(time.monotonic() - t0, 3))
        return row
    finally:
        shutil.rmtree(tmp, ignore_errors=True)


def _publish(tmp: str, final: str) -> None:
    """Rename the complete folder into place (an older result is moved aside first, then removed)."""
    if os.path.exists(final):
        old = f"{os.path.dirname(final)}/.{os.path.basename(final)}.old-{os.getpid()}-{time.time_ns()}"
        os.rename(final, old)
        shutil.rmtree(old, ignore_errors=True)
    os.rename(tmp, final)
    fd = os.open(os.path.dirname(final), os.O_RDONLY)
    try:
        os.fsync(fd)
    finally:
        os.close(fd)


def summary_row(report: dict, reused: bool) -> dict:
    seg = report.get("segmentation", {})
    ev = report.get("evaluation")
    return {"subject": report["subject"], "status": "ok", "reused": int(reused), "voxels": seg.get("voxels"),
            "volume_mm3": seg.get("volume_mm3"), "dice": ev.get("dice") if ev else "",
            "iterations": seg.get("iterations"), "stop": seg.get("stop"), "seconds": round(report.get("seconds", 0.0), 3),
            "error": ""}


def write_summary(out: str, rows: list) -> str:
    """DIR/summary.csv, written to a temporary and renamed."""
    buf = io.StringIO()
    w = csv.DictWriter(buf, fieldnames=SUMMARY_COLUMNS, extrasaction="ignore", lineterminator="\n")
    w.writeheader()
    for r in rows:
        w.writerow({k: ("" if r.get(k) is None else r.get(k)) for k in SUMMARY_COLUMNS})
    path = os.path.join(out, "summary.csv")
    tmp = os.path.join(out, f".summary.csv.tmp-{os.getpid()}")
    with open(tmp, "w", encoding="utf-8") as f:
        f.write(buf.getvalue())
        f.flush()
        os.fsync(f.fileno())
    os.replace(tmp, path)
    return path


class _Progress:
    """A one-line progress bar on stderr, only on a terminal."""

    def __init__(self, total: int, enabled: bool):
        self.total, self.done, self.failed = total, 0, 0
        self.enabled = enabled and sys.stderr.isatty()

    def update(self, row: dict) -> None:
        self.done += 1
        self.failed += row["status"] != "ok"
        if self.enabled:
            width = 30
            fill = width * self.done // max(1, self.total)
            sys.stderr.write(f"\rliveset batch [{'#' * fill}{'.' * (width - fill)}] {self.done}/{self.total}"
                             f"{f', {self.failed} failed' if self.failed else ''}   ")
            sys.stderr.flush()

    def close(self) -> None:
        if self.enabled:
            sys.stderr.write("\n")


def local_cluster(workers: int):
    """A LocalCluster of `workers` processes (one task thread each) whose scheduler, workers and
    nannies listen on 127.0.0.1 only, their HTTP endpoints (health, metrics; the dashboard when
    bokeh is installed) too, on free ports."""
    from distributed import LocalCluster
    return LocalCluster(n_workers=workers, threads_per_worker=1, processes=True, host="127.0.0.1",
                        dashboard_address="127.0.0.1:0", worker_dashboard_address="127.0.0.1:0", protocol="tcp://",
                        silence_logs=logging.ERROR)


def connect(scheduler: str, timeout: float = 10.0, tls: dict | None = None):
    """A Client of a running scheduler; ConnectionError with one line naming the address."""
    from distributed import Client
    from distributed.security import Security
    security = None
    if tls and any(tls.values()):
        security = Security(tls_ca_file=tls.get("ca"), tls_client_cert=tls.get("cert"),
                            tls_client_key=tls.get("key"), require_encryption=True)
    try:
        return Client(scheduler, timeout=timeout, security=security) if security else Client(scheduler, timeout=timeout)
    except Exception as e:  # OSError, TimeoutError, ValueError (bad address), ssl errors
        raise ConnectionError(f"cannot reach the Dask scheduler at {scheduler}: {' '.join(str(e).split()) or type(e).__name__}") from None


def run(manifest: str, out: str, workers: int | None = None, scheduler: str | None = None, *,
        threads: int | None = None, retries: int = 2, write_mesh: bool = False, progress: bool = True,
        tls: dict | None = None, connect_timeout: float = 10.0, client=None) -> list:
    """Process a cohort; returns the summary rows (also in DIR/summary.csv). Raises ManifestError
    / ConnectionError (one line) before any work when the manifest or the scheduler is bad.

    workers: LocalCluster size (default: the number of cores); scheduler: address of a running
    scheduler instead; client: an existing distributed.Client instead of both. threads: liveset
    threads per task (default: cores / workers locally, all cores on a remote cluster)."""
    subjects = read_manifest(manifest)
    if workers is not None and scheduler is not None:
        raise ValueError("give workers or scheduler, not both")
    if workers is not None and workers < 1:
        raise ValueError("workers must be at least 1")
    os.makedirs(out, exist_ok=True)
    if not os.access(out, os.W_OK):
        raise ManifestError(f"output folder '{out}' is not writable")
    for stale in glob.glob(os.path.join(out, ".*.tmp-*")) + glob.glob(os.path.join(out, ".*.old-*")):
        shutil.rmtree(stale, ignore_errors=True) if os.path.isdir(stale) else os.remove(stale)
    fingerprints = {s.subject: s.fingerprint() for s in subjects}
    rows, todo = {}, []
    for s in subjects:
        report = finished(out, s, fingerprints[s.subject])
        if report is not None:
            rows[s.subject] = summary_row(report, reused=True)
        else:
            todo.append(s)
    cluster, own_client = None, client is None
    if todo and client is None:
        if scheduler:
            client = connect(scheduler, timeout=connect_timeout, tls=tls)
        else:
            n = workers or os.cpu_count() or 1
            cluster = local_cluster(n)
            from distributed import Client
            client = Client(cluster)
            threads = threads if threads is not None else max(1, (os.cpu_count() or 1) // n)
    try:
        if todo:
            _run_tasks(client, todo, out, fingerprints, threads or 0, retries, write_mesh, progress, rows)
    finally:
        if own_client and client is not None:
            client.close()
        if cluster is not None:
            cluster.close()
    ordered = [rows[s.subject] for s in subjects]
    write_summary(out, ordered)
    return ordered


def _run_tasks(client, todo, out, fingerprints, threads, retries, write_mesh, progress, rows) -> None:
    from distributed import as_completed
    futures = {}
    for s in todo:
        f = client.submit(process_subject, s, os.path.abspath(out), fingerprints[s.subject], threads, write_mesh,
                          key=f"liveset-{s.subject}-{fingerprints[s.subject]}", retries=retries, pure=False)
        futures[f] = s
    bar = _Progress(len(todo), progress)
    try:
        for f in as_completed(list(futures)):
            s = futures[f]
            try:
                row = f.result()
            except Exception as e:  # KilledWorker after too many worker deaths, a lost scheduler, ...
                row = {"subject": s.subject, "status": "failed", "reused": 0,
                       "error": f"{type(e).__name__}: {' '.join(str(e).split())}"}
            rows[s.subject] = row
            bar.update(row)
    finally:
        bar.close()


def main(argv=None) -> int:
    p = argparse.ArgumentParser(prog="liveset batch", description=__doc__.split("\n\n")[0],
                                formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("manifest", help="CSV with a header: subject,image,seeds[,roi,mu_raw,epsilon_raw,truth,label,...]")
    p.add_argument("--out", required=True, help="output folder: DIR/<subject>/ and DIR/summary.csv")
    where = p.add_mutually_exclusive_group()
    where.add_argument("--workers", type=int, help="LocalCluster worker processes on this machine (default: cores)")
    where.add_argument("--scheduler", help="address of a running Dask scheduler (tcp://host:8786, tls://host:8786)")
    p.add_argument("--threads", type=int, help="liveset threads per subject (default: cores / workers locally)")
    p.add_argument("--retries", type=int, default=2, help="Dask retries of a subject whose task raised (default 2)")
    p.add_argument("--mesh", action="store_true", help="also write DIR/<subject>/surface.ply")
    p.add_argument("--tls-ca-file", help="CA certificate (default: Dask's distributed.comm.tls.ca-file)")
    p.add_argument("--tls-cert", help="client certificate (default: distributed.comm.tls.client.cert)")
    p.add_argument("--tls-key", help="client key (default: distributed.comm.tls.client.key)")
    p.add_argument("--connect-timeout", type=float, default=10.0, help="seconds to wait for --scheduler (default 10)")
    p.add_argument("--no-progress", action="store_true", help="no progress bar")
    p.add_argument("--json", action="store_true", help="print the summary rows as JSON on stdout")
    a = p.parse_args(argv)
    if a.workers is not None and a.workers < 1:
        p.error("--workers must be at least 1")
    tls = {"ca": a.tls_ca_file, "cert": a.tls_cert, "key": a.tls_key}
    if any(tls.values()) and not (a.scheduler or "").startswith("tls://"):
        p.error("--tls-* options need --scheduler tls://...")
    try:
        rows = run(a.manifest, a.out, a.workers, a.scheduler, threads=a.threads, retries=a.retries,
                   write_mesh=a.mesh, progress=not a.no_progress, tls=tls,
                   connect_timeout=a.connect_timeout)
    except (ManifestError, ConnectionError, ValueError) as e:
        print(f"liveset batch: error: {e}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        print("liveset batch: interrupted; finished subjects are kept, a re-run resumes", file=sys.stderr)
        return 130
    failed = [r for r in rows if r["status"] != "ok"]
    if a.json:
        print(json.dumps(rows))
    else:
        reused = sum(int(r["reused"]) for r in rows)
        print(f"liveset batch: {len(rows) - len(failed)}/{len(rows)} subjects ok ({reused} from an earlier run), "
              f"{len(failed)} failed; summary in {os.path.join(a.out, 'summary.csv')}")
    for r in failed:
        print(f"liveset batch: {r['subject']}: {r['error']}", file=sys.stderr)
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
