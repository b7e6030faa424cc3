"""A stage runs from its own module (``python -m graspaug.pipeline.stages.<stage>``, dvc.yaml's cmd) under the
exit-code contract every ``graspaug`` command keeps."""

import os
import subprocess
import sys
from pathlib import Path

SRC = Path(__file__).resolve().parents[2] / "src"


def stage(tmp_path: Path, module: str, *args: str) -> subprocess.CompletedProcess:
    env = {**os.environ, "PYTHONPATH": f"{SRC}{os.pathsep}{os.environ.get('PYTHONPATH', '')}"}
    command = [sys.executable, "-m", f"graspaug.pipeline.stages.{module}", *args]
    return subprocess.run(command, cwd=tmp_path, env=env, capture_output=True, text=True, timeout=120)


def test_a_stage_runs_from_its_own_module_and_keeps_the_exit_codes(tmp_path):
    """check_params from its module: 0 on a good file (the stage logs its line), 2 and one line naming the key on a
    mistyped one, 2 naming the file when it is missing."""
    (tmp_path / "good.yaml").write_text("seed: 3\n")
    (tmp_path / "bad.yaml").write_text("sede: 3\n")
    good = stage(tmp_path, "check_params", "--params", "good.yaml")
    assert good.returncode == 0, good.stderr
    assert "every key of params.yaml is known" in good.stderr and "(seed 3)" in good.stderr
    bad = stage(tmp_path, "check_params", "-p", "bad.yaml")
    assert bad.returncode == 2 and bad.stderr.startswith("error: sede: unknown key") and bad.stderr.count("\n") == 1
    missing = stage(tmp_path, "check_params")
    assert missing.returncode == 2 and "params.yaml" in missing.stderr and "Traceback" not in missing.stderr


def test_a_stage_option_is_parsed_before_any_work(tmp_path):
    """A bad ``--round`` of the lifelong stage is a usage error (exit 2) naming the option; ``--help`` shows the
    stage's own options."""
    refused = stage(tmp_path, "lifelong", "--round", "r0")
    assert refused.returncode == 2 and "--round" in refused.stderr and "k >= 1" in refused.stderr
    shown = stage(tmp_path, "grasps", "--help")
    assert shown.returncode == 0 and "--corpus" in shown.stdout and "--params" in shown.stdout
