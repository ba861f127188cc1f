"""Atomic writes: a SIGKILLed writer's temporary file is swept by the next write; live and foreign ones stay."""

import os
import signal
import subprocess
import sys

from ddmm.utils.files import _tag, atomic_write, sweep_stale_parts

_WRITER = """
import sys, time
from pathlib import Path
from ddmm.utils.files import atomic_write

def write(tmp):
    Path(tmp).write_text("half")
    print("writing", flush=True)
    time.sleep(60)

atomic_write(Path(sys.argv[1]), write)
"""


def test_a_killed_writer_leaves_a_part_the_next_write_sweeps(tmp_path):
    target = tmp_path / "run.nc"
    proc = subprocess.Popen([sys.executable, "-c", _WRITER, str(target)], stdout=subprocess.PIPE, text=True)
    assert proc.stdout.readline().strip() == "writing"
    os.kill(proc.pid, signal.SIGKILL)
    proc.wait()
    parts = [p for p in tmp_path.iterdir() if p.name.startswith(".run.nc")]
    assert len(parts) == 1 and str(proc.pid) in parts[0].name and not target.exists()
    atomic_write(tmp_path / "other.nc", lambda tmp: open(tmp, "w").write("x"))
    assert sorted(p.name for p in tmp_path.iterdir()) == ["other.nc"]


def test_live_and_foreign_parts_are_kept(tmp_path):
    live = tmp_path / f".a.nc{_tag()}xyz.part"  # this process: alive
    foreign = tmp_path / ".b.nc.ddmm-otherhost-1-xyz.part"
    unrelated = tmp_path / ".c.nc.part"
    for p in (live, foreign, unrelated):
        p.write_text("x")
    assert sweep_stale_parts(tmp_path) == []
    assert live.exists() and foreign.exists() and unrelated.exists()


def test_a_failed_write_leaves_nothing(tmp_path):
    def fail(tmp):
        open(tmp, "w").write("half")
        raise RuntimeError("disk full")

    try:
        atomic_write(tmp_path / "x.nc", fail)
    except RuntimeError:
        pass
    assert list(tmp_path.iterdir()) == []
