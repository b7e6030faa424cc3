"""Real pybullet, a real gso100 mesh: the oracle arm picks a feasible object with the cell's own hand."""

from __future__ import annotations

from pathlib import Path

import pandas as pd
import pytest

from graspaug.experiments.cell.trials import ORACLE, ObjectJob, run_object
from graspaug.planning.settings import CEMSettings, SamplerSettings
from graspaug.sim.settings import CellLayout, HandSettings

GSO100 = Path(__file__).resolve().parents[2] / ".." / "shared" / "corpora" / "gso100"


@pytest.mark.skipif(not GSO100.is_dir(), reason="gso100 is absent")
def test_the_oracle_picks_a_feasible_gso100_object(sim_cache):
    from graspaug.geometry.loading import load_shape
    from graspaug.geometry.prepare import prepare_shape
    from graspaug.geometry.settings import SurfaceSettings
    from graspaug.sim.feasibility import feasibility
    from graspaug.sim.objects import prepare_object

    name = "AllergenFree_JarroDophilus"  # a 5.4 cm bottle, 9.6 cm long
    mesh = prepare_shape(load_shape(GSO100 / f"{name}.obj"), SurfaceSettings(size="real")).mesh
    assert feasibility(mesh, 0.08)["feasible"]
    body = prepare_object(name, mesh, sim_cache, mass=0.25, lateral_friction=0.5)
    job = ObjectJob(ORACLE, 0, None, name, "test_shape", body, (2, 3, 4), (7, 8, 9), False)
    rows = run_object(job, CellLayout(), HandSettings(), SamplerSettings(), CEMSettings(), 96, 32)
    table = pd.DataFrame(rows)
    assert table.success.sum() >= 2, table[["outcome", "oracle_eps", "oracle_tilt", "contacts"]]
    assert (table.oracle_eps.dropna() > 0).all() and (table.oracle_tilt.dropna() <= 0.175).all()
