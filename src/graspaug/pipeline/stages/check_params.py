"""Stage ``check_params``: the whole params.yaml checked before any other stage runs.

It is the first stage of ``dvc.yaml`` and depends on the whole file, so every ``dvc repro`` (and ``dvc exp run``)
that follows an edit of params.yaml runs it first: a mistyped key or a bad value stops the run here, with one line
naming the key, before any stage has deleted its outputs to run again. It writes nothing.
"""

from __future__ import annotations

import logging

from graspaug.pipeline.params.model import Params

log = logging.getLogger(__name__)

__all__ = ["Params", "run"]


def run(params: Params) -> None:
    log.info("check_params: every key of params.yaml is known and every value valid (seed %d)", params.seed)


if __name__ == "__main__":
    from graspaug.pipeline.entry import stage_main

    stage_main(__spec__.name)
