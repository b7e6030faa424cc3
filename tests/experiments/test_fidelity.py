"""Chamfer distance, coverage, MMD and 1-NN accuracy on hand-made point clouds."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest
import trimesh

from graspaug.experiments.fidelity.numbers import (
    FIGURES,
    HEADLINE,
    chamfer_matrix,
    coverage_mmd,
    distribution_distances,
    fidelity_headline,
    fidelity_table,
    mesh_graspness,
    one_nn_accuracy,
    paired_graspness_kept,
    pool_shapes,
    resampled_distances,
    surface_cloud,
)
from graspaug.experiments.fidelity.words import fidelity_markdown, paired_graspness_kept_markdown
from graspaug.grasping.labelled import grasps_of_shape
from graspaug.grasping.settings import GraspsSettings


def test_chamfer_of_a_cloud_and_its_shift():
    a = np.zeros((1, 3))
    b = np.array([[0.003, 0.004, 0.0]])
    assert np.isclose(chamfer_matrix([a], [b])[0, 0], 0.005)
    square = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [1, 1, 0]], float)
    assert chamfer_matrix([square], [square])[0, 0] == 0.0
    assert np.isclose(chamfer_matrix([square], [square[:1]])[0, 0], 0.5 * (np.mean([0, 1, 1, np.sqrt(2)]) + 0))


def test_coverage_and_mmd_by_hand():
    d = np.array([[0.1, 0.5, 0.9], [0.2, 0.4, 0.8]])  # both pool shapes are nearest to reference 0
    coverage, mmd = coverage_mmd(d)
    assert coverage == pytest.approx(1 / 3) and mmd == pytest.approx((0.1 + 0.4 + 0.8) / 3)


def test_one_nn_accuracy_is_one_for_separate_sets_and_half_for_interleaved_ones():
    near = np.array([[0, 1], [1, 0]], float)
    far = np.full((2, 2), 10.0)
    assert one_nn_accuracy(near, near, far) == 1.0  # every shape's nearest is in its own set
    close = np.full((2, 2), 0.1)
    assert one_nn_accuracy(near, near, close) == 0.0  # every shape's nearest is in the other set
    with pytest.raises(ValueError, match="square"):
        one_nn_accuracy(near, near, np.ones((2, 3)))


def test_a_pool_of_the_reference_shapes_is_indistinguishable_and_boxes_are_not():
    rng = np.random.default_rng(0)
    spheres = [trimesh.creation.icosphere(radius=r) for r in (0.02, 0.025, 0.03, 0.035)]
    reference = [surface_cloud(m, 256, rng) for m in spheres]
    again = [surface_cloud(m, 256, rng) for m in spheres]  # the same shapes, other points
    same = distribution_distances(again, reference)
    # each shape's nearest is its twin in the other set; MMD is the sampling noise of 256 points (a few mm)
    assert same["coverage"] == 1.0 and same["one_nna"] == 0.0 and same["mmd"] < 0.005
    boxes = [surface_cloud(trimesh.creation.box((0.1, 0.01, 0.01 * k)), 256, rng) for k in (1, 2, 3, 4)]
    other = distribution_distances(boxes, reference)
    assert other["one_nna"] == 1.0 and other["coverage"] < 0.5 and other["mmd"] > 3 * same["mmd"]


def _spheres(radii, rng, points=128):
    return [surface_cloud(trimesh.creation.icosphere(radius=r), points, rng) for r in radii]


def test_resampled_distances_at_the_identity_are_the_plain_ones_and_copies_are_not_neighbours():
    rng = np.random.default_rng(1)
    pool, reference = _spheres((0.02, 0.03, 0.04), rng), _spheres((0.021, 0.031, 0.041), rng)
    pp, rr, pr = chamfer_matrix(pool, pool), chamfer_matrix(reference, reference), chamfer_matrix(pool, reference)
    identity = np.arange(3)
    assert resampled_distances(pp, rr, pr, identity, identity) == pytest.approx(distribution_distances(pool, reference))
    # a resample holding one pool shape three times: its copies are not each other's nearest shapes
    copies = resampled_distances(pp, rr, pr, np.array([0, 0, 0]), identity)
    assert copies["one_nna"] < 1.0
    with pytest.raises(ValueError, match="one size"):
        resampled_distances(pp, rr, pr, identity, identity[:2])


def test_pool_shapes_reads_graspness_datapoints_and_the_parents_mix():
    meshes = {"c0": trimesh.creation.box((0.01, 0.03, 0.02)), "c1": trimesh.creation.icosphere(radius=0.02)}
    graspness = {"a": 0.4, "b": 0.2, "c0": 0.3}  # c1 had no sampled grasp
    rendered = pd.DataFrame({"shape_id": ["c0", "c0", "c0", "c1"], "label": [1, 0, 0, 1]})
    parents = pd.DataFrame(
        {"shape_id": ["c1", "c0"], "parent_a": ["a", "a"], "parent_b": ["b", "a"], "alpha": [0.25, 0]}
    )
    pool = pool_shapes(meshes, graspness, rendered, 64, 0, parents)
    assert pool.ids == ["c0", "c1"] and pool.graspness.tolist() == [0.3, 0.0]
    assert pool.parents == pytest.approx([0.4, 0.75 * 0.4 + 0.25 * 0.2])
    assert pool.datapoints.tolist() == [3, 1] and pool.positives.tolist() == [1, 1]
    assert pool.extents[0] == pytest.approx([0.01, 0.02, 0.03]) and pool.distinct_parents == 2
    assert pool.alphas == {"0": 1, "0.25": 1} and len(pool.clouds) == 2 and pool.clouds[0].shape == (64, 3)
    again = pool_shapes(meshes, graspness, rendered, 64, 0, parents)  # each shape's points: its own seeded stream
    assert np.array_equal(again.clouds[1], pool.clouds[1])
    real = pool_shapes(meshes, graspness, rendered, 64, 0)
    assert np.isnan(real.parents).all() and real.distinct_parents is None and real.alphas == {}
    assert np.isnan(real.parent_datapoints).all() and np.isnan(pool.parent_datapoints).all()  # no counts given
    counted = pool_shapes(meshes, graspness, rendered, 64, 0, parents, {"a": 6, "b": 2})
    assert counted.parent_datapoints == pytest.approx([6, 0.75 * 6 + 0.25 * 2])  # mixed as the child mixes them
    kept = fidelity_table({"c": counted}, counted.clouds, 50, np.random.default_rng(0)).iloc[0]
    assert kept.datapoints_kept == pytest.approx(4 / (6 + 5)) and kept.datapoints_kept_lo <= kept.datapoints_kept


def test_fidelity_table_gives_intervals_that_hold_the_values_and_tell_a_far_pool_from_a_near_one():
    rng = np.random.default_rng(2)
    radii = np.linspace(0.02, 0.04, 8)
    reference = _spheres(radii, rng)
    rendered = pd.DataFrame({"shape_id": [f"s{i}" for i in range(8) for _ in range(i + 1)], "label": 1})
    near = {f"s{i}": trimesh.creation.icosphere(radius=r + 0.0005) for i, r in enumerate(radii)}
    far = {f"s{i}": trimesh.creation.box((0.1, 0.01, 0.005 * (i + 1))) for i in range(8)}
    graspness = {f"s{i}": 0.1 * (i % 3) for i in range(8)}
    pools = {name: pool_shapes(m, graspness, rendered, 128, 0) for name, m in (("near", near), ("far", far))}
    table = fidelity_table(pools, reference, 200, np.random.default_rng(0)).set_index("pool")
    for figure in FIGURES:
        if figure not in ("graspness_kept", "datapoints_kept"):  # real shapes keep no parents' figures
            assert (table[f"{figure}_lo"] <= table[figure] + 1e-12).all() and (
                table[figure] <= table[f"{figure}_hi"] + 1e-12
            ).all()
    assert table.graspness_kept.isna().all() and table.datapoints_kept.isna().all()
    assert table.datapoints_per_shape.tolist() == [4.5, 4.5]
    assert table.loc["near", "one_nna_hi"] < table.loc["far", "one_nna_lo"]
    assert table.loc["far", "one_nna"] == 1.0 and table.loc["near", "coverage"] > table.loc["far", "coverage"]
    headline = fidelity_headline(table.reset_index())  # one metrics file per pool and figure; real shapes keep none
    kept = ("graspness_kept", "datapoints_kept")
    assert set(headline) == {f"{p}_{f}" for p in ("near", "far") for f in HEADLINE if f not in kept}
    assert headline["far_one_nna"] == {"mean": 1.0, "lo": 1.0, "hi": 1.0}
    assert "| near | 8 | - |" in fidelity_markdown(table.reset_index(), 8, len(reference))


def test_graspness_kept_is_the_ratio_of_paired_means_with_an_interval_around_it():
    before = np.array([0.4, 0.5, 0.6, 0.3, 0.5])
    same = paired_graspness_kept(before.copy(), before)
    assert same["kept"] == pytest.approx(1.0) and same["difference"] == pytest.approx(0.0)
    halved = paired_graspness_kept(before / 2 + np.array([0.01, -0.01, 0.0, 0.01, -0.01]), before)
    assert halved["kept"] == pytest.approx(0.5, abs=0.01)
    assert halved["kept_low"] < halved["kept"] < halved["kept_high"] < 1.0
    assert halved["difference"] == pytest.approx(-before.mean() / 2, abs=0.01)
    table = paired_graspness_kept_markdown(pd.DataFrame([{"variant": "half", "shapes": 5, "meshed": 5} | halved]))
    assert "| half | 5 | 5 | 0.460 → 0.230 | 50.0% [" in table


def test_mesh_graspness_is_the_grasps_stages_share_of_positive_grasps(tmp_path):
    path = tmp_path / "box.obj"
    trimesh.creation.box((0.04, 0.05, 0.06)).export(path)
    settings = GraspsSettings()
    score, count = mesh_graspness(path, "box", settings, 3)
    table, _ = grasps_of_shape(path, "box", settings, 3)
    assert count == len(table) > 0 and score == pytest.approx(table.success.mean())


def test_a_figure_undefined_on_the_shapes_drawn_says_so_and_the_table_is_still_made():
    """Own meshes whose parents all have graspness 0 (every resample draws such parents), a pool with no rendered
    datapoints, parents without datapoints: each ratio over 0 is undefined (NaN), named with its reason in the
    table and in the report, never a ZeroDivisionError that stops the fidelity stage."""
    from graspaug.experiments.fidelity.numbers import coverage_mmd, heldout_summary

    meshes = {f"c{i}": trimesh.creation.box((0.01 * (i + 1), 0.03, 0.02)) for i in range(3)}
    graspness = {"a": 0.0, "b": 0.0, "c0": 0.2, "c1": 0.0, "c2": 0.1}
    parents = pd.DataFrame({"shape_id": list(meshes), "parent_a": "a", "parent_b": "b", "alpha": 0.5})
    rendered = pd.DataFrame({"shape_id": pd.Series(dtype=str), "label": pd.Series(dtype=int)})  # none rendered
    pool = pool_shapes(meshes, graspness, rendered, 64, 0, parents, {"a": 0, "b": 0})
    reference = pool_shapes(meshes, graspness, rendered, 64, 1).clouds
    table = fidelity_table({"own": pool}, reference, 50, np.random.default_rng(0))
    row = table.iloc[0]
    assert row.graspness == pytest.approx(0.1) and np.isfinite(row.one_nna)
    for figure in ("graspness_kept", "positive_share", "datapoints_kept"):
        assert pd.isna(row[figure]) and figure in row.undefined
    assert "the parents' graspness is 0" in row.undefined and "no datapoints" in row.undefined
    report = fidelity_markdown(table, 3, len(reference))
    assert "undefined: the parents' graspness is 0" in report and "undefined: no datapoints" in report
    assert "Undefined figures" in report
    assert set(fidelity_headline(table)) == {"own_datapoints_per_shape", "own_one_nna"}  # no NaN metric written

    # parents whose graspness is 0 on some resamples only: the point value stands, those resamples are named
    some = pool_shapes(meshes, graspness | {"a": 0.3}, rendered, 64, 0, parents.assign(parent_a=["a", "b", "b"]))
    kept = fidelity_table({"some": some}, reference, 200, np.random.default_rng(0)).iloc[0]
    assert np.isfinite(kept.graspness_kept) and "resamples (left out of its interval)" in kept.undefined
    assert "graspness_kept" in kept.undefined and kept.graspness_kept_lo <= kept.graspness_kept
    assert np.isnan(coverage_mmd(np.zeros((0, 0)))).all()

    per_shape = pd.DataFrame(
        {
            "meshed": [True, True],
            **{f"graspness_{w}": [0.1, 0.2] for w in ("before", "after")},
            **{f"{k}_{w}": [0, 0] for k in ("datapoints", "positives") for w in ("before", "after")},
            **{f"{k}_{w}": [1.0, 2.0] for k in ("stable_poses", "grasps_rendered") for w in ("before", "after")},
        }
    )
    summary = heldout_summary(per_shape)
    assert np.isnan(summary["positive_before"]) and np.isnan(summary["positive_after"])
