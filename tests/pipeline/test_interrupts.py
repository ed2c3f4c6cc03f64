"""Ctrl-C and SIGTERM end a running stage within seconds, leaving no process behind and no
partial file under the output's name."""

import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

from tests.conftest import copy_pipeline
from vnrrt.config import compose, dump


def group_alive(pgid: int) -> list[int]:
    """PIDs of live (not zombie) processes in process group ``pgid``."""
    alive = []
    for entry in Path("/proc").iterdir():
        if not entry.name.isdigit():
            continue
        try:
            fields = (entry / "stat").read_text().rsplit(")", 1)[1].split()
        except OSError:
            continue
        if int(fields[2]) == pgid and fields[0] != "Z":
            alive.append(int(entry.name))
    return alive


def sigint_default() -> None:
    """In the child before it runs: SIGINT at its default, as in a terminal. A test run
    started in the background (``make test &``) inherits SIGINT ignored, and Python then keeps
    it ignored, so the Ctrl-C these tests send would not reach the stage at all."""
    signal.signal(signal.SIGINT, signal.SIG_DFL)


@pytest.mark.parametrize(
    ("sig", "target"),
    [(signal.SIGINT, "group"), (signal.SIGINT, "parent"), (signal.SIGTERM, "parent")],
)
def test_a_signal_ends_a_shard_stage_within_seconds_and_leaves_nothing(tmp_path, repo, sig,
                                                                       target):  # fmt: skip
    """Ctrl-C in a terminal signals the whole process group; `kill` or a scheduler signals
    the stage's process alone, whose pool workers must then not be left running."""
    work = copy_pipeline(repo, tmp_path)
    cfg = compose(["scale=quick", "scale.maps_per_shard=3000", "workers=2"])
    (work / "params.yaml").write_text(dump(cfg))
    env = dict(os.environ, PYTHONUNBUFFERED="1")
    proc = subprocess.Popen([sys.executable, "stages/shard.py", "--shard", "0"], cwd=work,
                            env=env, stdout=subprocess.PIPE, stderr=subprocess.STDOUT,
                            start_new_session=True, preexec_fn=sigint_default)  # fmt: skip
    time.sleep(4.0)  # the pool is up and working (3,000 maps take far longer)
    assert proc.poll() is None, proc.stdout.read().decode()
    workers = [p for p in group_alive(proc.pid) if p != proc.pid]
    assert workers, "no pool workers started"
    if target == "group":
        os.killpg(proc.pid, sig)
    else:
        os.kill(proc.pid, sig)
    start = time.monotonic()
    try:
        proc.wait(timeout=10)
    except subprocess.TimeoutExpired:
        os.killpg(proc.pid, signal.SIGKILL)
        pytest.fail("the stage did not stop within 10 s")
    assert time.monotonic() - start < 10 and proc.returncode != 0
    time.sleep(0.5)
    assert group_alive(proc.pid) == [], "processes survived the stage"
    shards = work / cfg.paths.shards
    assert not (shards / "shard_0.npz").exists() and not list(shards.glob("*.tmp-*"))


SLOW_START = """
import multiprocessing.process as mpp, time
from vnrrt.infra.parallel import parallel_map

start = mpp.BaseProcess.start


def slow_start(self):  # a worker forked, not yet recorded by the pool for 1.5 s
    start(self)
    print("forked", flush=True)
    time.sleep(1.5)


def work(x):
    time.sleep(0.05)
    return x


if __name__ == "__main__":
    mpp.BaseProcess.start = slow_start
    parallel_map(work, list(range(2000)), workers=2)
"""


@pytest.mark.parametrize(("sig", "target"), [(signal.SIGINT, "group"), (signal.SIGTERM, "parent")])
def test_a_signal_while_the_workers_start_leaves_no_worker_behind(tmp_path, sig, target):
    """A signal between a worker's fork and the pool recording it (a loaded machine's timing)
    still ends everything: before the fix, that worker was left running and the exit hung."""
    script = tmp_path / "slow_start.py"
    script.write_text(SLOW_START)
    proc = subprocess.Popen([sys.executable, str(script)], stdout=subprocess.PIPE,
                            stderr=subprocess.STDOUT, start_new_session=True,
                            preexec_fn=sigint_default)  # fmt: skip
    assert proc.stdout.readline().strip() == b"forked"  # the signal lands inside slow_start
    (os.killpg if target == "group" else os.kill)(proc.pid, sig)
    try:
        proc.wait(timeout=10)
    except subprocess.TimeoutExpired:
        os.killpg(proc.pid, signal.SIGKILL)
        pytest.fail("the process did not stop within 10 s")
    assert proc.returncode != 0
    time.sleep(0.5)
    assert group_alive(proc.pid) == [], "processes survived"
