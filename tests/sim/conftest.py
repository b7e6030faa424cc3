"""Objects for the simulation tests, decomposed once per session into a temporary cache."""

from __future__ import annotations

import pytest


@pytest.fixture(scope="session")
def sim_cache(tmp_path_factory):
    return tmp_path_factory.mktemp("sim-cache")


@pytest.fixture(scope="session")
def cube(sim_cache):
    """pybullet_data's toy cube (5.2 × 5.2 × 3.9 cm), 0.1 kg."""
    from graspaug.sim.objects import everyday_mesh, prepare_object

    return prepare_object("cube", everyday_mesh("cube"), sim_cache, mass=0.1, lateral_friction=0.5)


@pytest.fixture(scope="session")
def duck(sim_cache):
    from graspaug.sim.objects import everyday_mesh, prepare_object

    return prepare_object("duck", everyday_mesh("duck"), sim_cache, mass=0.1, lateral_friction=0.5)
