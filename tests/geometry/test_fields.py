"""Field grids and surface finishing (:mod:`graspaug.geometry.fields`): the decimator's failures are counted and
logged, never silent."""

import logging

import trimesh

from graspaug.geometry.fields import decimate, over_budget_counts, reset_over_budget_counts


def test_decimation_meets_the_budget_and_counts_nothing():
    sphere = trimesh.creation.icosphere(subdivisions=4)  # 5120 faces
    reset_over_budget_counts()
    small = decimate(sphere, face_budget=500)
    assert len(small.faces) < 1000 and small.is_watertight and small.body_count == 1  # near the budget
    assert over_budget_counts() == {}
    assert decimate(sphere, face_budget=10_000) is sphere  # under the budget: untouched


def test_a_failing_decimator_is_logged_and_counted(caplog):
    """fast-simplification raises (here: a target of -1 faces, ValueError at every setting); the mesh comes back
    whole and over the budget, with a warning naming the exception and a count the stage can report."""
    sphere = trimesh.creation.icosphere(subdivisions=2)
    reset_over_budget_counts()
    with caplog.at_level(logging.WARNING, logger="graspaug.geometry.fields"):
        out = decimate(sphere, face_budget=-1)
        decimate(sphere, face_budget=-1)
    assert out is sphere and out.is_watertight
    assert over_budget_counts() == {"raised": 2}
    warned = [r.getMessage() for r in caplog.records if r.name == "graspaug.geometry.fields"]
    assert len(warned) == 2 and "ValueError" in warned[0] and "320 faces, over the budget of -1" in warned[0], warned
