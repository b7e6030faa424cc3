"""Atomic writes survive a killed writer: nothing under the final name, leftovers cleaned later."""

import os
import signal
import subprocess
import sys
import textwrap

from graspaug.io.atomic import atomic_path

KILLED_WRITER = textwrap.dedent("""
    import os, signal, sys
    from graspaug.io.atomic import atomic_path
    with atomic_path(sys.argv[1], directory=True) as tmp:
        (tmp / "half.txt").write_text("half")
        os.kill(os.getpid(), signal.SIGKILL)
""")


def test_killed_writer_leaves_nothing_under_the_final_name_and_the_next_write_cleans_up(tmp_path):
    target = tmp_path / "out"
    result = subprocess.run([sys.executable, "-c", KILLED_WRITER, str(target)])
    assert result.returncode == -signal.SIGKILL
    leftovers = list(tmp_path.glob(".out.tmp-*"))
    assert not target.exists() and len(leftovers) == 1 and (leftovers[0] / "half.txt").exists()
    with atomic_path(target, directory=True) as tmp:
        (tmp / "whole.txt").write_text("whole")
    assert sorted(os.listdir(tmp_path)) == ["out"] and (target / "whole.txt").read_text() == "whole"


def test_failed_block_keeps_the_old_file(tmp_path):
    target = tmp_path / "table.csv"
    target.write_text("old")
    try:
        with atomic_path(target) as tmp:
            tmp.write_text("new, half")
            raise RuntimeError("disk full")
    except RuntimeError:
        pass
    assert target.read_text() == "old" and sorted(os.listdir(tmp_path)) == ["table.csv"]


LOCK_HOLDER = textwrap.dedent("""
    import sys, time
    from pathlib import Path
    from graspaug.io.atomic import exclusive_lock
    with exclusive_lock(sys.argv[1]):
        Path(sys.argv[2]).write_text("held")
        time.sleep(1.0)
        Path(sys.argv[2]).write_text("whole")
""")


def test_a_second_writer_waits_for_the_lock_and_then_sees_the_first_ones_work(tmp_path):
    """Two evaluate runs on one fresh cache: the second failed on the first's vanished temporary folder; now the
    second waits for the first's lock, then reads what it wrote."""
    import time

    from graspaug.io.atomic import exclusive_lock

    lock, work = tmp_path / "cache/.key.lock", tmp_path / "work.txt"
    first = subprocess.Popen([sys.executable, "-c", LOCK_HOLDER, str(lock), str(work)])
    while not work.exists():
        time.sleep(0.02)
    start = time.perf_counter()
    with exclusive_lock(lock):
        waited = time.perf_counter() - start
        assert work.read_text() == "whole"
    assert first.wait() == 0 and waited > 0.5
