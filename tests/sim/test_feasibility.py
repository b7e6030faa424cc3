"""Which objects a parallel jaw can hold, from geometry alone: real stable poses, real meshes."""

from __future__ import annotations

from pathlib import Path

import pytest
import trimesh

from graspaug.sim.feasibility import feasibility, least_width

GSO100 = Path(__file__).resolve().parents[2] / ".." / "shared" / "corpora" / "gso100"


def test_least_width_of_a_rotated_rectangle():
    box = trimesh.creation.box(extents=[0.03, 0.12, 0.01])
    box.apply_transform(trimesh.transformations.rotation_matrix(0.7, [0, 0, 1]))
    assert least_width(box.vertices[:, :2]) == pytest.approx(0.03)


def test_a_jaw_holds_a_small_block_but_not_a_wide_plate_or_a_flat_card():
    assert feasibility(trimesh.creation.box(extents=[0.05, 0.06, 0.04]), 0.08)["feasible"]
    assert not feasibility(trimesh.creation.box(extents=[0.12, 0.12, 0.09]), 0.08)["feasible"]  # wider than 7 cm
    assert not feasibility(trimesh.creation.box(extents=[0.05, 0.05, 0.008]), 0.08)["feasible"]  # lies too flat


def test_a_ball_rests_too_and_is_judged_as_it_lands():
    small, large = trimesh.creation.icosphere(3, 0.02), trimesh.creation.icosphere(3, 0.05)
    assert feasibility(small, 0.08)["feasible"] and not feasibility(large, 0.08)["feasible"]


@pytest.mark.skipif(not GSO100.is_dir(), reason="gso100 is absent")
def test_gso100_a_bottle_is_feasible_a_plant_saucer_is_not():
    from graspaug.geometry.loading import load_shape
    from graspaug.geometry.prepare import prepare_shape
    from graspaug.geometry.settings import SurfaceSettings

    def mesh(name):
        return prepare_shape(load_shape(GSO100 / f"{name}.obj"), SurfaceSettings(size="real")).mesh

    assert feasibility(mesh("AllergenFree_JarroDophilus"), 0.08)["share"] > 0.9
    assert feasibility(mesh("Ecoforms_Plant_Container_S14Turquoise"), 0.08)["share"] == 0.0
