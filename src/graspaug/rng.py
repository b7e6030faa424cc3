"""Random streams that do not depend on worker count or processing order."""

from __future__ import annotations

import zlib

import numpy as np


def shape_rng(seed: int, shape_id: str, purpose: str = "") -> np.random.Generator:
    """The random stream of one shape for one ``purpose`` (``""`` for grasp sampling): fixed by
    ``seed``, the id and the purpose, whatever the worker or order."""
    key = [seed, zlib.crc32(shape_id.encode())]
    if purpose:
        key.append(zlib.crc32(purpose.encode()))
    return np.random.default_rng(key)
