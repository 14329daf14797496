"""``symstab reproduce`` stopped by a signal: workers gone, nothing left behind.

The command is run as a subprocess and interrupted once its worker
processes are busy with the audit and the figures; it must stop them, remove
its temporary folder, print one line and exit with 128 + the signal number,
within seconds (it used to wait for the running tasks, a minute and more, and
SIGTERM left the folder and both workers behind).
"""

import os
import pathlib
import signal
import subprocess
import sys
import time

import pytest


def _children(pid):
    """Pids of the living descendants of ``pid`` (psutil if installed, else /proc)."""
    try:
        import psutil
    except ImportError:
        psutil = None
    if psutil is not None:
        try:
            return {p.pid for p in psutil.Process(pid).children(recursive=True)}
        except psutil.NoSuchProcess:
            return set()
    parents = {}
    for entry in pathlib.Path("/proc").iterdir():
        if entry.name.isdigit():
            try:
                stat = (entry / "stat").read_text()
            except OSError:
                continue
            parents.setdefault(int(stat.rsplit(")", 1)[1].split()[1]), []).append(int(entry.name))
    found, todo = set(), [pid]
    while todo:
        for child in parents.get(todo.pop(), []):
            found.add(child)
            todo.append(child)
    return found


def _alive(pid):
    """True while ``pid`` runs (a zombie, dead but not yet reaped, is not alive)."""
    try:
        state = pathlib.Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()[0]
    except OSError:
        return False
    return state not in ("Z", "X")


@pytest.mark.slow
@pytest.mark.skipif(not pathlib.Path("/proc/self/stat").exists(), reason="needs /proc (Linux)")
@pytest.mark.parametrize("signum, status", [(signal.SIGINT, 130), (signal.SIGTERM, 143)],
                         ids=["SIGINT", "SIGTERM"])
def test_a_signal_stops_reproduce_at_once_and_cleanly(tmp_path, signum, status):
    proc = subprocess.Popen([sys.executable, "-m", "symstab", "reproduce", "--out", "out"],
                            cwd=tmp_path, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                            text=True, start_new_session=True)
    try:
        # Wait for stage 2 (the workers), then give them time to get busy.
        lines, deadline = [], time.monotonic() + 600
        while time.monotonic() < deadline:
            line = proc.stderr.readline()
            assert line, f"reproduce ended before its workers started: {''.join(lines)}"
            lines.append(line)
            if line.startswith("[2/3]"):
                break
        # The workers are forked (no imports to wait for): once both are
        # there, a second more and they are inside their first figures.
        wait_until = time.monotonic() + 3
        while len(_children(proc.pid)) < 2 and time.monotonic() < wait_until:
            time.sleep(0.05)
        time.sleep(1)
        workers = _children(proc.pid)
        assert len(workers) >= 2, f"expected the worker processes, found {workers}"
        assert list(tmp_path.glob(".out.*")), "no temporary folder while reproduce runs"
        sent = time.monotonic()
        if signum == signal.SIGINT:
            os.killpg(proc.pid, signum)   # Ctrl-C reaches the whole process group
        else:
            os.kill(proc.pid, signum)     # kill -TERM <pid>
        _, err = proc.communicate(timeout=60)
        took = time.monotonic() - sent
    finally:
        if proc.poll() is None:
            os.killpg(proc.pid, signal.SIGKILL)
            proc.wait()
    assert proc.returncode == status, err
    assert took < 5, f"took {took:.1f} s to stop"
    assert "Traceback" not in err, err
    said = err.strip().splitlines()
    assert said[-1] == "symstab reproduce: interrupted" and said.count(said[-1]) == 1, err
    assert list(tmp_path.iterdir()) == [], "left behind: " + ", ".join(
        p.name for p in tmp_path.iterdir())
    deadline = time.monotonic() + 2
    while any(_alive(pid) for pid in workers) and time.monotonic() < deadline:
        time.sleep(0.05)
    assert not [pid for pid in workers if _alive(pid)], "worker processes survived"
