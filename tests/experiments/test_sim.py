"""The sim experiment's arms and pictures, on networks and rows made by hand in a temporary folder."""

import numpy as np
import pytest

from graspaug.errors import DataError
from graspaug.experiments.cell.figures import trial_picture
from graspaug.experiments.cell.trials import arms, model_path


def seed_dirs_with(tmp_path, networks: list[str], seeds=(0, 1)) -> dict:
    """Training seed → its folder, holding an empty ``model.pt`` for each network name."""
    dirs = {s: tmp_path / f"s{s}" for s in seeds}
    for folder in dirs.values():
        for name in networks:
            (folder / name).mkdir(parents=True, exist_ok=True)
            (folder / name / "model.pt").write_bytes(b"")
    return dirs


def test_arms_pair_before_and_after_and_add_real_only_when_every_seed_has_it(tmp_path):
    dirs = seed_dirs_with(tmp_path, ["targeted/50-0", "targeted/50-1.5"])
    assert model_path(dirs[0], 50, 0.0, "real") == dirs[0] / "targeted/50-0/model.pt"  # ratio 0 is the targeted network
    expected = {
        "before": ("targeted", 0.0, 50),
        "after": ("targeted", 1.5, 50),
        "antipodal": (None, None, None),  # the floor
        "oracle": (None, None, None),  # the ceiling: on every run, as the floor
    }
    assert arms(1.5, 50, dirs, (50, 200)) == expected  # no B = 200 network: no positive control arm
    seed_dirs_with(tmp_path, ["real/50-1.5", "targeted/100-0"])
    chosen = arms(1.5, 50, dirs, (50, 100, 200))
    assert chosen["real"] == ("real", 1.5, 50) and "more_real" not in chosen  # the largest B, 200, is missing
    seed_dirs_with(tmp_path, ["targeted/200-0"])
    assert arms(1.5, 50, dirs, (50, 100, 200))["more_real"] == ("targeted", 0.0, 200)  # as the AP's real_data
    with pytest.raises(DataError, match=r"s0/targeted/50-2/model.pt is missing"):
        arms(2.0, 50, dirs)


def test_a_picture_shows_the_jaws_around_the_grasp_and_blanks_missing_pixels():
    depth = np.full((100, 200), 0.6)
    depth[0, 0] = 0.0
    row = {
        "_depth": depth,
        "u": 150.0,
        "v": 40.0,
        "angle": 0.0,
        "width_px": 20.0,
        "quality": 0.8,
        "object": "duck",
        "arm": "after",
        "seed": 1,
        "outcome": "success",
        "_frames": [],
    }
    picture = trial_picture(row, 1.5)
    np.testing.assert_allclose(picture["jaw"], [[140.0, 40.0], [160.0, 40.0]])
    assert np.isnan(picture["depth"][0, 0]) and picture["window"] == (100, 0, 200, 100)
    assert picture["title"] == "duck, arm after (ratio 1.5, training seed 1), attempt 0: Q = 0.800 → success"


def test_the_after_ratio_comes_from_the_report_or_is_the_largest():
    from graspaug.experiments.cell.trials import after_ratio

    assert after_ratio({"summary": {"50": {"best_ratio": 1.5}}}, 50, [0.0, 0.5, 2.0]) == (1.5, True)
    assert after_ratio({"summary": {"100": {"best_ratio": 1.5}}}, 50, [0.0, 0.5, 2.0]) == (2.0, False)
    assert after_ratio({}, 50, [0, 1]) == (1.0, False)


def test_no_user_folder_gives_no_meshes_and_a_bad_one_is_a_data_error(tmp_path):
    from types import SimpleNamespace

    from graspaug.experiments.cell.trials import user_meshes

    ingest = SimpleNamespace(surface=None, max_faces=10, max_file_mb=1.0)
    assert user_meshes(None, ingest) == ([], {})
    with pytest.raises(DataError, match="holds no mesh file"):
        user_meshes(tmp_path, ingest)


def test_the_plan_line_counts_objects_arms_and_seeds():
    from types import SimpleNamespace

    from graspaug.experiments.cell.trials import trials_plan

    chosen = {"before": ("targeted", 0.0, 50), "after": ("targeted", 1.5, 50), "antipodal": (None, None, None)}
    objects = [SimpleNamespace(name="a"), SimpleNamespace(name="b")]
    assert trials_plan(objects, chosen, 3, 2, {"x.obj": "empty"}) == (
        "2 objects × 3 attempts; arms before, after, antipodal × 2 training seeds (after = ratio 1.5); 1 skipped meshes"
    )
    feasible = {"a": {"feasible": True}, "b": {"feasible": False}}  # object_feasibility's, judged before the picks
    assert trials_plan(objects, chosen, 3, 2, {}, feasible).endswith("; 0 skipped meshes; 1 feasible objects")


def test_the_oracle_picks_each_object_once_on_the_drops_of_every_other_arm(tmp_path):
    from types import SimpleNamespace

    from graspaug.experiments.cell.trials import object_jobs

    dirs = seed_dirs_with(tmp_path, ["targeted/50-0", "targeted/50-1"])
    chosen = arms(1.0, 50, dirs)
    objects = [SimpleNamespace(name=name, kind="everyday", body=None) for name in ("cube", "duck")]
    jobs = object_jobs(objects, chosen, dirs, attempts=3, seed=7, n_pictures=2)
    oracle = [j for j in jobs if j.arm == "oracle"]
    assert [j.name for j in oracle] == ["cube", "duck"] and {(j.seed, j.model) for j in oracle} == {(-1, None)}
    for job in oracle:  # the same drops and planner seeds as every arm's, every training seed's
        others = [j for j in jobs if j.name == job.name and j.arm != "oracle"]
        assert len(others) == 5 and all(
            (j.drop_seeds, j.plan_seeds) == (job.drop_seeds, job.plan_seeds) for j in others
        )
    assert not any(j.record for j in oracle)  # no depth image to draw
    assert all(j.record for j in jobs if j.arm == "antipodal")  # n_pictures = 2: both objects' first attempts


def test_feasibility_is_judged_on_the_cells_meshes_and_marks_every_attempt(tmp_path):
    """Real meshes in the files the cell loads: a 5 × 5 × 4 cm box fits the 80 mm jaw, a 12 cm cube does not; the
    trials table carries each object's verdict on every attempt, whatever the arm."""
    from types import SimpleNamespace

    import pandas as pd
    import trimesh

    from graspaug.experiments.cell.trials import object_feasibility, trials_table

    objects = []
    for name, extents in (("small", (0.05, 0.05, 0.04)), ("large", (0.12, 0.12, 0.12))):
        path = tmp_path / f"{name}.obj"
        trimesh.creation.box(extents).export(path)
        objects.append(SimpleNamespace(name=name, body=SimpleNamespace(visual=path)))
    rule = object_feasibility(objects, 0.08)
    assert rule["small"]["feasible"] and rule["small"]["share"] == 1.0
    assert not rule["large"]["feasible"] and rule["large"]["share"] == 0.0
    rows = [
        {"arm": arm, "seed": seed, "object": name, "attempt": 0, "success": False, "_depth": None}
        for arm, seed in (("before", 0), ("antipodal", -1), ("oracle", -1))
        for name in ("small", "large")
    ]
    trials = trials_table(rows, arms(1.0, 50, seed_dirs_with(tmp_path, ["targeted/50-0", "targeted/50-1"])), rule)
    assert trials.groupby("object").feasible.agg(set).to_dict() == {"large": {False}, "small": {True}}
    assert trials.feasible_share.tolist() == [1.0, 0.0] * 3 and "_depth" not in trials
    assert pd.isna(trials.ratio[trials.arm == "oracle"]).all()
