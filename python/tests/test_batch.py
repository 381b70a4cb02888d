"""liveset batch on Dask: 8 phantom subjects on a 2-worker LocalCluster give the CLI's masks bit
for bit; a corrupt subject is recorded while the others finish; a worker killed mid-subject loses
nothing; a re-run recomputes nothing; bad manifests fail before any work with one line."""
import csv
import glob
import os
import shutil
import signal
import subprocess
import sys
import time

import nibabel as nib
import numpy as np
import pytest

from conftest import CLI, cli, make_phantom, seed_args

SUBJECTS = 8


@pytest.fixture(scope="module")
def cohort(tmp_path_factory):
    """8 phantoms (seeds 1..8) with their CLI masks, and a manifest (relative paths) plus one
    corrupt subject (a truncated image) in a second manifest."""
    root = tmp_path_factory.mktemp("cohort")
    rows, ref = [], {}
    for k in range(1, SUBJECTS + 1):
        d = root / f"s{k}"
        info = make_phantom(str(d), seed=k)
        seeds = seed_args(info)
        args = ["segment", d / "t1.nii.gz", "--out-mask", d / "cli_mask.nii.gz", "--quiet"]
        for s in seeds:
            args += ["--seed", s]
        cli(*args)
        ref[f"sub-{k:02d}"] = np.asarray(nib.load(str(d / "cli_mask.nii.gz")).dataobj)
        rows.append([f"sub-{k:02d}", f"s{k}/t1.nii.gz", ";".join(seeds), f"s{k}/truth_gm.nii.gz", "1"])
    header = ["subject", "image", "seeds", "truth", "label"]
    write_csv(root / "manifest.csv", header, rows)
    data = (root / "s1" / "t1.nii.gz").read_bytes()
    (root / "corrupt.nii.gz").write_bytes(data[: len(data) // 2])
    write_csv(root / "with_corrupt.csv", header, rows + [["sub-bad", "corrupt.nii.gz", rows[0][2], "", ""]])
    return {"root": root, "ref": ref}


def write_csv(path, header, rows):
    with open(path, "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(header)
        w.writerows(rows)


def batch(*args, via_cli=False, **kw):
    cmd = [CLI, "batch"] if via_cli else [sys.executable, "-m", "liveset.batch"]
    return subprocess.run([*cmd, *map(str, args), "--no-progress"], capture_output=True, text=True, **kw)


def summary(out):
    with open(os.path.join(out, "summary.csv"), newline="") as f:
        return {r["subject"]: r for r in csv.DictReader(f)}


def assert_masks_match(out, ref):
    for subject, mask in ref.items():
        got = nib.load(os.path.join(out, subject, "mask.nii.gz"))
        assert np.array_equal(np.asarray(got.dataobj), mask), subject
        assert os.path.exists(os.path.join(out, subject, "phi.nii.gz"))


def test_cohort_with_a_corrupt_subject_then_rerun(cohort, tmp_path):
    out = tmp_path / "out"
    r = batch(cohort["root"] / "with_corrupt.csv", "--out", out, "--workers", 2, via_cli=True)
    assert r.returncode == 1, r.stderr
    rows = summary(out)
    assert len(rows) == SUBJECTS + 1
    assert rows["sub-bad"]["status"] == "failed" and "corrupt.nii.gz" in rows["sub-bad"]["error"]
    assert not os.path.exists(out / "sub-bad")
    for k in range(1, SUBJECTS + 1):
        row = rows[f"sub-{k:02d}"]
        assert row["status"] == "ok" and row["reused"] == "0" and 0.5 < float(row["dice"]) <= 1.0
        assert int(row["iterations"]) > 0 and float(row["volume_mm3"]) > 0
    assert_masks_match(out, cohort["ref"])
    assert "sub-bad" in r.stderr and not glob.glob(str(out / ".*"))
    stamps = {p: os.stat(p).st_mtime_ns for p in glob.glob(str(out / "sub-*" / "*"))}
    r2 = batch(cohort["root"] / "with_corrupt.csv", "--out", out, "--workers", 2)
    assert r2.returncode == 1
    rows2 = summary(out)
    assert all(rows2[s]["reused"] == "1" for s in cohort["ref"]) and rows2["sub-bad"]["status"] == "failed"
    assert {p: os.stat(p).st_mtime_ns for p in glob.glob(str(out / "sub-*" / "*"))} == stamps


def test_worker_killed_mid_subject_loses_nothing(cohort, tmp_path):
    out = tmp_path / "out"
    p = subprocess.Popen([sys.executable, "-m", "liveset.batch", str(cohort["root"] / "manifest.csv"), "--out",
                          str(out), "--workers", "2", "--no-progress"], stdout=subprocess.PIPE,
                         stderr=subprocess.PIPE, text=True)
    killed, deadline = None, time.monotonic() + 120
    while killed is None and p.poll() is None and time.monotonic() < deadline:
        for tmp in glob.glob(str(out / ".sub-*.tmp-*")):  # a subject in progress: .<subject>.tmp-<pid>-<ns>
            pid = int(tmp.rsplit(".tmp-", 1)[1].split("-")[0])
            try:
                os.kill(pid, signal.SIGKILL)
                killed = (os.path.basename(tmp).split(".tmp-")[0][1:], pid)
            except ProcessLookupError:
                continue
            break
        time.sleep(0.002)
    stdout, stderr = p.communicate(timeout=300)
    assert killed is not None, "no subject was seen in progress"
    assert p.returncode == 0, stderr
    rows = summary(out)
    assert all(rows[s]["status"] == "ok" for s in cohort["ref"]), rows
    assert_masks_match(out, cohort["ref"])


@pytest.mark.parametrize("header,row,message", [
    ("subject,image", "a,s1/t1.nii.gz", "missing column(s) seeds"),
    ("subject,image,seeds", "a,s1/nope.nii.gz,\"1,2,3\"", "row 2: image 's1/nope.nii.gz' does not exist"),
    ("subject,image,seeds", "a,s1/t1.nii.gz,1;2;3", "row 2: bad seed '1'"),
    ("subject,image,seeds,mu_raw", "a,s1/t1.nii.gz,\"1,2,3\",high", "row 2: mu_raw 'high' is not a number"),
    ("subject,image,seeds", "a,s1/t1.nii.gz,\"1,2,3;1,2,480\"", "row 2: seed 1,2,480 lies outside the image (48x48x48"),
    ("subject,image,seeds", "a,s1/phantom.json,\"1,2,3\"", "row 2: image: cannot read"),
    ("subject,image,seeds,colour", "a,s1/t1.nii.gz,\"1,2,3\",red", "unknown column(s) colour"),
    ("subject,image,seeds,smooth_mm", "a,s1/t1.nii.gz,\"1,2,3\",0.5", "row 2: smooth_mm needs alpha"),
])
def test_bad_manifest_one_line_before_any_work(cohort, tmp_path, header, row, message):
    m = cohort["root"] / "bad.csv"
    m.write_text(header + "\n" + row + "\n")
    r = batch(m, "--out", tmp_path / "out", "--workers", 1, via_cli=True)
    assert r.returncode == 2 and message in r.stderr and r.stderr.count("\n") == 1, r.stderr
    assert not glob.glob(str(tmp_path / "out" / "*"))


def test_duplicate_subject_and_unreachable_scheduler(cohort, tmp_path):
    m = cohort["root"] / "dup.csv"
    m.write_text('subject,image,seeds\na,s1/t1.nii.gz,"1,2,3"\nb,s2/t1.nii.gz,"1,2,3"\na,s3/t1.nii.gz,"1,2,3"\n')
    r = batch(m, "--out", tmp_path / "o1")
    assert r.returncode == 2 and "row 4: subject 'a' repeats row 2" in r.stderr
    r = batch(cohort["root"] / "manifest.csv", "--out", tmp_path / "o2", "--scheduler", "tcp://127.0.0.1:9",
              "--connect-timeout", "2")
    assert r.returncode == 2 and "cannot reach the Dask scheduler at tcp://127.0.0.1:9" in r.stderr
    assert r.stderr.count("\n") == 1 and not glob.glob(str(tmp_path / "o2" / "sub-*"))


def listening_addresses(pid):
    """Local addresses of the TCP sockets process `pid` listens on (from /proc)."""
    inodes = set()
    for fd in glob.glob(f"/proc/{pid}/fd/*"):
        try:
            link = os.readlink(fd)
        except OSError:
            continue
        if link.startswith("socket:["):
            inodes.add(link[8:-1])
    found = []
    for table in (f"/proc/{pid}/net/tcp", f"/proc/{pid}/net/tcp6"):
        with open(table) as f:
            next(f)
            for line in f:
                cols = line.split()
                if cols[3] == "0A" and cols[9] in inodes:  # LISTEN
                    found.append(cols[1].split(":")[0])
    return found


def test_local_cluster_listens_on_loopback_only():
    from distributed import Client
    from liveset.batch import local_cluster
    with local_cluster(2) as cluster, Client(cluster) as client:
        info = client.scheduler_info()
        assert info["address"].startswith("tcp://127.0.0.1:")
        assert all(a.startswith("tcp://127.0.0.1:") for a in info["workers"])
        pids = [os.getpid(), *client.run(os.getpid).values(), *client.run(os.getppid).values()]  # + nannies
        addresses = [a for pid in pids for a in listening_addresses(pid)]
        assert addresses and all(a == "0100007F" for a in addresses), addresses  # 127.0.0.1


def test_tls_scheduler_with_dask_certificates(cohort, tmp_path):
    """A scheduler and a worker speaking TLS with mutual certificates (as docs/PYTHON.md shows):
    batch with the client certificate gives the CLI's masks; without it, one line and no work."""
    if not shutil.which("openssl"):
        pytest.skip("openssl missing (scripts/setup.sh installs it)")
    c = tmp_path / "certs"
    c.mkdir()
    run = lambda *a: subprocess.run(list(a), cwd=c, check=True, capture_output=True)  # noqa: E731
    run("openssl", "req", "-x509", "-newkey", "rsa:2048", "-nodes", "-days", "2", "-subj", "/CN=ca",
        "-keyout", "ca-key.pem", "-out", "ca.pem")
    for r in ("scheduler", "worker", "client"):
        run("openssl", "req", "-newkey", "rsa:2048", "-nodes", "-subj", f"/CN={r}", "-keyout", f"{r}-key.pem",
            "-out", f"{r}.csr")
        run("openssl", "x509", "-req", "-in", f"{r}.csr", "-CA", "ca.pem", "-CAkey", "ca-key.pem",
            "-CAcreateserial", "-days", "2", "-out", f"{r}.pem")
    tls = lambda r: ["--tls-ca-file", str(c / "ca.pem"), "--tls-cert", str(c / f"{r}.pem"),  # noqa: E731
                     "--tls-key", str(c / f"{r}-key.pem")]
    sched_file = tmp_path / "scheduler.json"
    dask = lambda role: [sys.executable, "-m", f"distributed.cli.dask_{role}"]  # noqa: E731 (Debian's, not PATH's)
    procs = [subprocess.Popen([*dask("scheduler"), "--protocol", "tls", "--host", "127.0.0.1", "--port", "0",
                               "--no-dashboard", "--scheduler-file", str(sched_file), *tls("scheduler")],
                              stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)]
    try:
        import json
        address, deadline = None, time.monotonic() + 60
        while address is None and time.monotonic() < deadline:  # the scheduler writes the file once listening
            try:
                address = json.loads(sched_file.read_text())["address"]
            except (OSError, ValueError, KeyError):
                time.sleep(0.1)
        assert address, "the TLS scheduler did not start"
        assert address.startswith("tls://127.0.0.1:")
        procs.append(subprocess.Popen([*dask("worker"), address, "--host", "127.0.0.1", "--nthreads", "1",
                                       "--no-dashboard", *tls("worker")], stdout=subprocess.DEVNULL,
                                      stderr=subprocess.DEVNULL))
        r = batch(cohort["root"] / "manifest.csv", "--out", tmp_path / "none", "--scheduler", address,
                  "--connect-timeout", "3")
        assert r.returncode == 2 and f"cannot reach the Dask scheduler at {address}" in r.stderr
        r = batch(cohort["root"] / "manifest.csv", "--out", tmp_path / "out", "--scheduler", address, *tls("client"),
                  via_cli=True)
        assert r.returncode == 0, r.stderr
        assert_masks_match(tmp_path / "out", cohort["ref"])
    finally:
        for p in reversed(procs):
            p.terminate()
            p.wait(timeout=30)
