"""Simulated robot trials: a pybullet Franka Panda picks objects from a table into a bin with
grasps a GQ-CNN plans on an overhead depth image (paper Section IV-E, in simulation)."""

import os as _os
import sys as _sys


def _import_pybullet_quietly() -> None:
    """Import pybullet with its C-level "pybullet build time: ..." banner on stderr silenced, so a command's output
    is its own lines (the module is then cached for every ``import pybullet`` of this package). Without pybullet
    (a GPU machine that trains networks only) the settings still import; a trial fails where it needs pybullet."""
    if "pybullet" in _sys.modules:
        return
    _sys.stderr.flush()
    saved, devnull = _os.dup(2), _os.open(_os.devnull, _os.O_WRONLY)
    try:
        _os.dup2(devnull, 2)
        import pybullet  # noqa: F401
    except ImportError:
        pass
    finally:
        _os.dup2(saved, 2)
        _os.close(saved)
        _os.close(devnull)


_import_pybullet_quietly()
