"""`graspaug study real-picks` (issue #76): the kept networks pick real household objects in the simulated cell, one
row per attempt; bad input is one line and exit 2."""

import json
import shutil

import numpy as np
import pandas as pd
import pytest
from typer.testing import CliRunner

from graspaug.experiments.cell.picks import (
    ANTIPODAL,
    hardest_objects,
    never_held,
    pick_power,
    pick_ranking,
    pick_summary,
)
from graspaug.experiments.cell.trials import ORACLE
from graspaug.pipeline.cli import app

KEPT = "results/attribution-real-objects-4000/networks"
SMALL = ("AllergenFree_JarroDophilus.obj", "3D_Dollhouse_TablePurple.obj")  # two of gso100's objects


def _picks(repo_root, monkeypatch, *args):
    monkeypatch.chdir(repo_root)
    return CliRunner().invoke(app, ["study", "real-picks", *args])


def test_pick_summary_reads_the_control_first_and_clusters_attempts_by_object():
    rng = np.random.default_rng(0)
    rows = []
    for draw in (0, 1, 2):
        for obj in range(20):
            easy = rng.random()
            for arm, gain in (("none@50", 0.0), ("targeted@50", 0.02), ("none@150", 0.3), (ANTIPODAL, -0.2)):
                for attempt in range(10):
                    success = rng.random() < np.clip(easy + gain, 0, 1)
                    rows.append({"draw": draw, "arm": arm, "object": f"d{draw}o{obj}", "attempt": attempt,
                                 "success": success})  # fmt: skip
    attempts = pd.DataFrame(rows)
    summary = pick_summary(attempts, ["none@50", "targeted@50", "none@150", ANTIPODAL])
    assert summary["control_shows"] and summary["contrasts"]["control"]["over"] == "draws"
    assert summary["contrasts"]["control"]["verdict"] == "higher"
    assert summary["contrasts"]["none@50_vs_antipodal"]["verdict"] == "higher"
    one = pick_summary(attempts[attempts.draw == 0], ["none@50", "targeted@50", "none@150"])
    assert one["contrasts"]["control"]["over"] == "objects" and one["contrasts"]["control"]["n"] == 20
    flat = attempts.assign(success=np.where(attempts.arm == "none@150", attempts.success.shift(40), attempts.success))
    flat = flat.fillna(False).assign(success=lambda t: t.success.astype(bool))
    unclear = pick_summary(flat[flat.arm != ANTIPODAL], ["none@50", "targeted@50", "none@150"])
    if not unclear["control_shows"]:
        assert unclear["contrasts"]["targeted_vs_none"]["verdict"].startswith("the cell cannot tell")
    assert len(hardest_objects(attempts, 5)) == 5 and isinstance(never_held(attempts), list)
    assert "ranking" not in summary  # no scores in this table
    power = pick_power(attempts[attempts.draw == 0], "none@150", "none@50", 70, [2, 4, 8], 0.1)
    assert power["pilot_objects"] == 20 and 0 < power["power"][2] < power["power"][4] <= power["power"][8] <= 1


def test_the_ranking_compares_networks_on_the_same_executed_grasps():
    """Every network scores every executed grasp: the one whose scores follow the outcomes ranks them better."""
    rng = np.random.default_rng(1)
    n = 3 * 25 * 8
    success = rng.random(n) < 0.3
    attempts = pd.DataFrame({
        "draw": np.repeat([0, 1, 2], n // 3), "object": np.repeat(np.arange(75), 8), "success": success,
        "score_none@50": rng.random(n), "score_targeted@50": rng.random(n),
        "score_none@150": np.clip(success * 0.4 + rng.random(n) * 0.6, 0, 1),
    })  # fmt: skip
    attempts.loc[::7, "score_none@50"] = np.nan  # no grasp planned: not an executed grasp
    ranking = pick_ranking(attempts)
    assert ranking["grasps"] == int(attempts["score_none@50"].notna().sum())
    assert ranking["arms"]["none@150"]["mean"] > 0.8 and abs(ranking["arms"]["none@50"]["mean"] - 0.5) < 0.1
    assert ranking["contrasts"]["control"]["verdict"] == "higher" and ranking["contrasts"]["control"]["over"] == "draws"
    assert ranking["contrasts"]["targeted_vs_none"]["verdict"] == "not shown (the interval holds zero)"
    one = pick_ranking(attempts[attempts.draw == 0])
    assert one["contrasts"]["control"]["over"] == "objects" and one["contrasts"]["control"]["n"] == 25
    flat = pick_ranking(attempts.assign(**{"score_none@150": rng.random(n)}))
    if not flat["control_shows"]:
        assert flat["contrasts"]["targeted_vs_none"]["verdict"].startswith("the cell cannot tell")


def test_the_kept_networks_pick_a_few_real_objects(repo_root, tmp_path, monkeypatch):
    corpus = repo_root.parent / "shared" / "corpora" / "gso100"
    if not corpus.is_dir():
        pytest.skip(f"{corpus} absent beside this clone")
    objects = tmp_path / "objects"
    objects.mkdir()
    for name in SMALL:
        shutil.copy(corpus / name, objects / name)
    out, kept = tmp_path / "out", str(repo_root / KEPT)
    shutil.copytree(repo_root / "profiles", tmp_path / "profiles")  # these d0-s0 cards predate test-set rules
    monkeypatch.chdir(tmp_path)  # --results writes results/<NAME>/ here, not into the repository
    pick = ["study", "real-picks", "--networks", kept, "--draws", "0", "--objects", str(objects), "--attempts", "2"]
    done = CliRunner().invoke(app, [*pick, "--workers", "2", "--out", str(out), "--results", "picks"])
    assert done.exit_code == 0, done.output
    table = pd.read_parquet(tmp_path / "results" / "picks" / "attempts.parquet")
    assert len(table) == 2 * 2 * 5 and set(table.draw) == {0} and set(table.arm) >= {ORACLE, ANTIPODAL}
    feasible = table.groupby("object").feasible.first()  # declared from geometry, the same in every arm
    bottle = next(o for o in feasible.index if o.endswith("allergenfree_jarrodophilus"))  # as evaluate names it
    assert feasible[bottle] and (table.groupby("object").feasible.nunique() == 1).all()
    assert table.contacts.notna().all() and (table.mass < 0.2).any() == (table.mass.min() < 0.2)
    table_by_images = table[table.arm != ORACLE]  # the oracle plans on the mesh: no image for a network to score
    scores = table_by_images[["score_none@50", "score_targeted@50", "score_none@100"]]  # every network, every grasp
    planned = table_by_images.outcome != "no_grasp"
    assert scores[planned].notna().all().all() and scores[~planned].isna().all().all()
    own = table_by_images[(table_by_images.arm == "none@50") & planned]
    assert np.allclose(own["score_none@50"], own.quality, atol=1e-5)  # a network's own grasp: the quality it planned
    again = CliRunner().invoke(app, [*pick, "--out", str(tmp_path / "again"), "--results", "picks"])
    assert again.exit_code == 0 and "in the results table already" in again.output, again.output
    assert pd.read_parquet(tmp_path / "results" / "picks" / "attempts.parquet").equals(table)  # not picked again
    other = CliRunner().invoke(app, [*pick[:-1], "3", "--out", str(tmp_path / "other"), "--results", "picks"])
    assert other.exit_code == 2 and "its draws have 2 attempts" in other.output, other.output
    summary = json.loads((out / "summary.json").read_text())
    assert set(summary["arms"]) == {"none@50", "targeted@50", "none@100", ANTIPODAL, ORACLE}
    assert summary["feasible"]["all_object_draws"] == 2 and summary["feasible"]["object_draws"] >= 1
    assert summary["attempts_per_arm"] == {arm: 4 for arm in summary["arms"]} and summary["objects"] == 2
    assert summary["contrasts"]["control"]["a"] == "none@100"  # the exploratory study kept B = 50 and 100
    report = (out / "report.md").read_text()
    assert report.splitlines()[2].startswith("Feasible objects first:") and "the oracle picks" in report
    assert "| paper (8 everyday objects, no interval) | 8 | 10 | 68% | 86% |" in report and "none@100" in report


def test_bad_input_is_one_line(repo_root, tmp_path, monkeypatch):
    (tmp_path / "empty").mkdir()
    empty = _picks(repo_root, monkeypatch, "--networks", KEPT, "--objects", str(tmp_path / "empty"),
                   "--out", str(tmp_path / "o1"))  # fmt: skip
    assert empty.exit_code == 2 and "holds no mesh file" in empty.output, empty.output
    missing = _picks(repo_root, monkeypatch, "--networks", KEPT, "--draws", "7", "--objects", str(tmp_path / "empty"),
                     "--out", str(tmp_path / "o2"))  # fmt: skip
    assert missing.exit_code == 2 and "draw 7: no networks in" in missing.output, missing.output
    params = tmp_path / "params.yaml"
    params.write_text("sim:\n  cell:\n    camera_height: 1.5\n")
    camera = _picks(repo_root, monkeypatch, "--networks", KEPT, "--draws", "0", "--objects", str(tmp_path / "empty"),
                    "--params", str(params), "--out", str(tmp_path / "o3"))  # fmt: skip
    assert camera.exit_code == 2 and "trained for a camera 0.65-0.75 m" in camera.output, camera.output
    assert not (tmp_path / "o1").exists() and not (tmp_path / "o3").exists()  # nothing half-written


def test_two_objects_carry_no_interval_and_the_report_says_so():
    """One draw of two objects: a bootstrap over two objects gives three values, no interval; the summary, its
    verdicts and the report say why instead of printing +0.000 [+0.000, +0.000]."""
    from graspaug.pipeline.studies.real_picks import report_markdown

    rows = [{"draw": 0, "arm": arm, "object": f"o{o}", "attempt": a, "success": bool((o + a) % 2)}
            for arm in ("none@50", "targeted@50", "none@150") for o in range(2) for a in range(4)]  # fmt: skip
    attempts = pd.DataFrame(rows)
    summary = pick_summary(attempts, ["none@50", "targeted@50", "none@150"]) | {"never_held": [], "attempts": 4}
    control = summary["contrasts"]["control"]
    assert control["low"] is None and control["high"] is None
    assert control["verdict"] == "no interval: 2 objects (an objects' bootstrap needs 5 or more)"
    report = report_markdown(attempts, summary)
    assert "[+0.000, +0.000]" not in report and "+0.000 (no interval: 2 objects" in report


def test_without_its_corpora_real_picks_says_which_corpus_it_needs(tmp_path, monkeypatch):
    """The defaults with no ../shared/corpora: exit 2, one line naming --corpora, the corpus and where it comes from
    (not an unexpected BadParameter)."""
    monkeypatch.chdir(tmp_path)
    out = CliRunner().invoke(app, ["study", "real-picks"])
    assert out.exit_code == 2, out.output
    assert len(out.output.strip().splitlines()) == 1 and "bug" not in out.output, out.output
    assert "--corpora: ../shared/corpora: no such folder" in out.output and "Google Scanned Objects" in out.output
    assert "--objects" in out.output


def test_objects_in_millimetres_load_with_unit_scale_in_evaluates_formats(tmp_path):
    """--objects reads every mesh evaluate reads (.off and .glb too) in --unit-scale metres per unit; mm files read
    as metres are skipped with advice that names an option real-picks has."""
    import trimesh

    from graspaug.pipeline.params.profiles import profile_params
    from graspaug.pipeline.studies.real_picks import corpus_meshes, object_sources

    objects = tmp_path / "objects"
    (objects / "sub").mkdir(parents=True)
    trimesh.creation.box(extents=[50, 30, 80]).export(objects / "box.off")
    trimesh.creation.cylinder(radius=20, height=90).export(objects / "sub" / "can.glb")
    surface = profile_params("real_objects").ingest.surface
    sources = object_sources(objects, 0.001)
    assert len(sources) == 2 and {s.path.suffix for s in sources} == {".off", ".glb"}
    meshes, missed = corpus_meshes(objects, [s.shape_id for s in sources], surface, None, 0.001)
    assert len(meshes) == 2 and not missed
    assert all(0.02 < max(m.extents) < 0.2 for _, m in meshes)  # real size, metres
    _, missed = corpus_meshes(objects, [s.shape_id for s in object_sources(objects, 1.0)], surface, None, 1.0)
    assert len(missed) == 2 and all("--unit-scale 0.001 (evaluate, study real-picks --objects)" in r
                                    for r in missed.values()), missed  # fmt: skip
    help_text = CliRunner().invoke(app, ["study", "real-picks", "--help"], env={"COLUMNS": "250"}).output
    assert "--unit-scale" in help_text and ".glb" in help_text


def test_the_papers_protocol_picks_feasible_objects_each_from_one_pose(repo_root, tmp_path, monkeypatch):
    corpus = repo_root.parent / "shared" / "corpora" / "gso100"
    if not corpus.is_dir():
        pytest.skip(f"{corpus} absent beside this clone")
    objects = tmp_path / "objects"
    objects.mkdir()
    for name in SMALL:  # a bottle (feasible) and a doll's table (not: 8% of its landings fit the jaw)
        shutil.copy(corpus / name, objects / name)
    shutil.copytree(repo_root / "profiles", tmp_path / "profiles")
    monkeypatch.chdir(tmp_path)
    out = tmp_path / "out"
    pick = ["study", "real-picks", "--networks", str(repo_root / KEPT), "--draws", "0", "--objects", str(objects)]
    done = CliRunner().invoke(app, [*pick, "--attempts", "2", "--paper", "3", "--out", str(out), "--results", "p"])
    assert done.exit_code == 0, done.output
    table = pd.read_parquet(tmp_path / "results" / "p" / "attempts.parquet")
    assert [o[-26:] for o in set(table.object)] == ["allergenfree_jarrodophilus"] and table.feasible.all()  # the rule
    oracle = table[table.arm == ORACLE]
    assert len(oracle) == 2 and oracle.grasp_x.nunique() == 1  # one pose: the oracle's grasp is the same each time
    assert json.loads((out / "summary.json").read_text())["protocol"].startswith("paper: 3 feasible objects")
    only = CliRunner().invoke(app, [*pick, "--attempts", "1", "--feasible-only", "--out", str(tmp_path / "only")])
    assert only.exit_code == 0, only.output
    summary = json.loads((tmp_path / "only" / "summary.json").read_text())
    assert summary["objects"] == 1 and any(k.endswith("3d_dollhouse_tablepurple") for k in summary["skipped"])


def test_the_committed_figures_of_a_table_with_feasibility_name_the_cells_fitness_and_each_arms_span():
    """``graspaug results``' picks figures of a table with ``feasible``: the count of feasible object-draws, whether
    the oracle's rate makes the cell fit to compare planners (at least 90%), and each arm's share of the oracle −
    antipodal span, from the feasible attempts alone."""
    from graspaug.experiments.results import picks_figures

    rows = []
    for o, feasible in ((0, True), (1, True), (2, False)):
        for arm, rate in (("oracle", 1.0), ("antipodal", 0.25), ("none@50", 0.75)):
            rows += [{"draw": 0, "arm": arm, "object": f"o{o}", "attempt": a, "success": a < 4 * rate,
                      "feasible": feasible} for a in range(4)]  # fmt: skip
    table = pd.DataFrame(rows)
    from graspaug.experiments.cell.picks import feasible_summary

    result = pick_summary(table, ["none@50", "oracle", "antipodal"], 200, 0) | {
        "feasible": feasible_summary(table, 200, 0)
    }
    figures = picks_figures(result, "p")
    assert figures["p/feasible/object_draws"] == "2 feasible object-draws of 3"
    assert figures["p/feasible/oracle_fit"] == "fit to compare planners"
    assert figures["p/feasible/span/none@50"] == "0.67" and figures["p/feasible/span/oracle"] == "1.00"


def test_the_sim_report_and_the_picks_read_feasibility_and_the_oracle_alike():
    """One reading of the feasible rows and of the oracle serves both tables: a missing ``feasible`` value is not
    feasible, a table without the column has no feasible row, and without an oracle arm there is no verdict and no
    span (the antipodal floor alone defines none)."""
    from graspaug.experiments.cell.picks import feasible_rows, oracle_readout

    table = pd.DataFrame({"feasible": [True, None, False, True]})
    assert feasible_rows(table).tolist() == [True, False, False, True]
    assert not feasible_rows(pd.DataFrame({"success": [True]})).any()
    assert oracle_readout({"antipodal": 0.5, "none@50": 0.7}) == {"oracle_rate": None, "oracle_fit": None,
                                                                 "span_share": {}}  # fmt: skip
    fit = oracle_readout({"oracle": 0.9, "antipodal": 0.5, "none@50": 0.7})
    assert fit["oracle_fit"] and fit["span_share"]["none@50"] == pytest.approx(0.5)
    assert not oracle_readout({"oracle": 0.89})["oracle_fit"]
