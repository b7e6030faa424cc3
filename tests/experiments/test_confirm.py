"""The confirmatory study's statistics and its plan's history (issue #74): the tests it reads, the order it reads
them in, and the git checks that the plan came first."""

import json
import subprocess

import numpy as np
import pandas as pd
import pytest
import yaml
from scipy import stats

from graspaug.errors import DataError
from graspaug.experiments.confirm import numbers as confirm
from graspaug.experiments.confirm.tables import check_plan_history, combine_confirm, read_plan, read_plan_result
from graspaug.experiments.confirm.words import confirm_figures

PLAN = {
    "format": "graspaug.confirm-plan/1",
    "question": "Does the paper's augmentation raise test AP on real objects?",
    "profile": "confirm",
    "draws": [0, 1, 2],
    "seeds": [0],
    "arms": {
        "none@50": ["targeted", 50, 0.0],
        "none@150": ["targeted", 150, 0.0],
        "targeted@50": ["targeted", 50, 1.0],
        "random@50": ["random", 50, 1.0],
    },
    "training_rule": "4,000 steps",
    "statistic": "t over draws",
    "alpha": 0.05,
    "control": {"name": "real_data", "a": "none@150", "b": "none@50"},
    "primary": {"name": "targeted_vs_none@50", "a": "targeted@50", "b": "none@50"},
    "secondary": [{"name": "targeted_vs_random@50", "a": "targeted@50", "b": "random@50", "margin": 0.03}],
    "power": {},
    "words": {
        "uninformative": "uninformative: the control did not show",
        "raises": "raises AP by {mean} [{low}, {high}], p = {p}",
        "lowers": "lowers AP by {mean}",
        "not_shown": "not shown: {mean} [{low}, {high}], p = {p}",
    },
}


def test_the_draw_test_is_a_one_sample_t_and_tost_holm_and_power_behave():
    x = [0.05, 0.01, 0.08, 0.03, -0.01, 0.06]
    t = confirm.draw_test(x)
    ref = stats.ttest_1samp(x, 0.0)
    assert t["p"] == pytest.approx(ref.pvalue) and t["mean"] == pytest.approx(np.mean(x))
    ci = ref.confidence_interval(0.95)
    assert (t["low"], t["high"]) == pytest.approx((ci.low, ci.high))
    assert confirm.draw_test([0.1])["low"] is None  # one draw: no interval
    # equivalence: a tight spread around 0 is equivalent within ±0.03, a wide one is not
    assert confirm.tost([0.001, -0.002, 0.003, 0.0, -0.001], 0.03)["p"] < 0.05
    assert confirm.tost([0.05, -0.06, 0.02, 0.0], 0.03)["p"] > 0.05
    assert confirm.holm({"a": 0.01, "b": 0.04, "c": None}) == {"a": 0.02, "b": 0.04, "c": None}
    assert confirm.holm({"a": 0.03, "b": 0.02}) == {"a": pytest.approx(0.04), "b": pytest.approx(0.04)}
    # how far the result rests on single draws: scipy's signed-rank test, the t with each draw left out
    s = confirm.draw_sensitivity(x)
    assert s["positive"] == 5 and s["n_draws"] == 6 and s["wilcoxon_p"] == pytest.approx(stats.wilcoxon(x).pvalue)
    left_out = [stats.ttest_1samp(np.delete(x, i), 0.0).pvalue for i in range(6)]
    assert s["loo_p"] == pytest.approx((min(left_out), max(left_out))) and confirm.draw_sensitivity(x[:2]) is None
    assert confirm.draw_sensitivity([0.0, 0.0, 0.0]) is None  # nothing to rank
    assert confirm.power(8, 0.05, 0.0) == pytest.approx(0.05, abs=1e-6)  # no effect: the false-positive rate
    assert confirm.power(8, 0.05, 0.03) < confirm.power(16, 0.05, 0.03) < confirm.power(16, 0.03, 0.03)
    n = confirm.draws_for_power(0.05, 0.03)
    assert confirm.power(n, 0.05, 0.03) >= 0.8 > confirm.power(n - 1, 0.05, 0.03)


def test_variance_components_and_the_seeds_that_cost_least():
    rng = np.random.default_rng(0)
    draws, seeds = 400, 4
    full = 0.02 * rng.standard_normal((draws, 1)) + 0.07 * rng.standard_normal((draws, seeds))
    resampled = full[..., None] + 0.01 * rng.standard_normal((draws, seeds, 50))
    parts = confirm.variance_components(full, resampled)
    assert parts["seed_sd"] == pytest.approx(0.07, rel=0.05) and parts["draw_sd"] == pytest.approx(0.02, rel=0.3)
    assert parts["object_sd"] == pytest.approx(0.01 / 2, rel=0.2)  # the mean of 4 seeds' independent noise
    rows = confirm.seeds_for_cost(parts, 0.03, draw_minutes=20, seed_minutes=9)
    assert rows[0]["hours"] == min(r["hours"] for r in rows) and 2 <= rows[0]["seeds"] <= 5


def test_coverage_of_the_draw_t_interval_is_simulated_from_networks():
    rng = np.random.default_rng(1)
    full = 0.05 + 0.06 * rng.standard_normal((5, 4))
    resampled = full[..., None] + 0.02 * rng.standard_normal((5, 4, 4000))
    c = confirm.simulate_coverage(full, resampled, n_draws=8, n_seeds=2, n_sims=500, rng=rng)
    assert 0.91 <= c["coverage"] <= 0.99 and c["n_sims"] == 500
    with pytest.raises(ValueError, match="need 8000"):
        confirm.simulate_coverage(full, resampled, n_draws=8, n_seeds=2, n_sims=1000, rng=rng)


def test_exchange_rate_is_read_only_inside_the_curve():
    sizes = [25, 50, 100, 150, 200]
    curve = np.array([[0.2, 0.3, 0.4, 0.45, 0.5]] * 4) + np.array([[0.0], [0.01], [-0.01], [0.005]])
    inside = confirm.exchange_rate_on_curve(sizes, curve, np.array([0.41, 0.40, 0.39, 0.405]))
    assert inside["worth"] == pytest.approx(100, abs=3) and inside["outside"] is None
    assert inside["low"] is not None and inside["low"] < 100 < inside["high"]
    above = confirm.exchange_rate_on_curve(sizes, curve, np.array([0.6, 0.61, 0.59, 0.6]))
    assert above["worth"] is None and above["outside"] == "above"


def test_the_exchange_rate_reads_each_draws_curve_on_its_own_sizes():
    """Each draw's own sizes (objects holding datapoints): the same sizes in every draw give the common curve's
    answer; a curve measured at fewer objects than nominal makes the same AP worth fewer objects."""
    sizes = np.array([25, 50, 100, 150, 200])
    curve = np.array([[0.2, 0.3, 0.4, 0.45, 0.5]] * 4) + np.array([[0.0], [0.01], [-0.01], [0.005]])
    arm = np.array([0.41, 0.40, 0.39, 0.405])
    common = confirm.exchange_rate_on_curve(sizes, curve, arm)
    same = confirm.exchange_rate_on_curve(np.tile(sizes, (4, 1)), curve, arm)
    assert {k: same[k] for k in ("worth", "low", "high")} == {k: common[k] for k in ("worth", "low", "high")}
    fewer = confirm.exchange_rate_on_curve(np.tile(sizes * 0.9, (4, 1)) + np.arange(4)[:, None], curve, arm)
    assert fewer["worth"] < common["worth"] and fewer["ends"][0] == pytest.approx(25 * 0.9 + 3)
    assert fewer["ends"][1] == pytest.approx(200 * 0.9)  # the grid stays where every draw was measured


def test_base_objects_count_what_each_draws_base_sets_hold(tmp_path):
    """The base sets on actual counts: drawn as train_gqcnn draws them, kept where the renders hold datapoints,
    nested, with the train split's size; checked against a networks table's datapoints."""
    from graspaug.experiments.confirm.tables import base_objects, check_base_objects

    ids = [f"s{i:02d}" for i in range(40)]
    objects = pd.DataFrame({"shape_id": ids, "duplicate_of": [""] * 40})
    rendered = ids[::2] + ids[1:20:2]  # half the odd shapes have no datapoint
    index = pd.DataFrame({"shape_id": np.repeat(rendered, 3)})
    (tmp_path / "original").mkdir()
    index.to_parquet(tmp_path / "original" / "index.parquet")
    counts = base_objects(objects, tmp_path / "original", [3, 4], [5, 10], 0.2, 3, 0)
    assert list(counts.columns) == ["draw", "base_size", "objects", "datapoints", "train_objects"]
    assert (counts.objects <= counts.base_size).all() and (counts.datapoints == 3 * counts.objects).all()
    assert (counts.train_objects == 32).all() and counts.objects.lt(counts.base_size).any()
    again = base_objects(objects, tmp_path / "original", [3, 4], [5, 10], 0.2, 3, 0)
    pd.testing.assert_frame_equal(counts, again)
    networks = counts.rename(columns={"datapoints": "train_datapoints"}).assign(ratio=0.0)
    check_base_objects(counts, networks)
    networks.loc[1, "train_datapoints"] += 1
    with pytest.raises(DataError, match=f"draw 3, base size {networks.base_size[1]}: its 1:0 network trained on"):
        check_base_objects(counts, networks)


def test_the_committed_base_objects_are_the_first_studys_and_read_the_worth_on_them():
    """results/real-objects-confirm/base-objects.parquet agrees with every 1:0 network's datapoints, and the worth
    read on actual counts lies below the nominal one (fewer objects hold datapoints than the base size names)."""
    from pathlib import Path

    from graspaug.experiments.confirm.tables import check_base_objects

    folder = Path(__file__).resolve().parents[2] / "results" / "real-objects-confirm"
    counts = pd.read_parquet(folder / "base-objects.parquet")
    check_base_objects(counts, pd.read_parquet(folder / "networks.parquet"))
    result = combine_confirm(folder)
    assert result["exchange_actual"]["worth"] < result["exchange"]["worth"]
    assert result["base_objects"]["max"] <= 50 < result["base_objects"]["train_objects_min"]


def test_the_plan_is_read_in_its_fixed_sequence():
    values = {
        d: {"none@50": 0.3, "none@150": 0.3 + c, "targeted@50": 0.3 + g, "random@50": 0.3 + g}
        for d, (c, g) in enumerate([(0.1, 0.05), (0.12, 0.06), (0.09, 0.04), (0.11, 0.05)])
    }
    shown = read_plan_result(PLAN, values)
    assert shown["control"]["shows"] and shown["primary"]["verdict"] == "raises"
    assert shown["sentence"].startswith("raises AP by +0.0500 [")
    assert shown["secondary"]["targeted_vs_random@50"]["verdict"] == "equivalent within ±0.03"
    figures = confirm_figures(shown | {"status": "complete", "complete": True}, "s")
    assert figures["s/primary/sensitivity"].startswith("above 0 in 4 of 4 draws; Wilcoxon p = 0.125; each draw left")
    assert figures["s/targeted_vs_random@50/equivalence"].startswith("TOST p = 0.000, its 90% interval [+0.0")
    # the same gain with a control that does not show: uninformative, never negative or positive
    flat = {d: v | {"none@150": v["none@50"] + (0.01 if d % 2 else -0.01)} for d, v in values.items()}
    assert read_plan_result(PLAN, flat)["primary"]["verdict"] == "uninformative"
    noisy = {d: v | {"targeted@50": v["none@50"] + (0.05 if d % 2 else -0.04)} for d, v in values.items()}
    assert read_plan_result(PLAN, noisy)["primary"]["verdict"] == "not shown"


def _git(folder, *args):
    subprocess.run(["git", *args], cwd=folder, check=True, capture_output=True)


def _draw_tables(folder, draws):
    rows = [
        {"draw": d, "pool": "targeted", "base_size": 50, "ratio": 0.0, "seed": 0, "train_steps": 4000} for d in draws
    ]
    pd.DataFrame(rows).to_parquet(folder / "networks.parquet", index=False)


def _repo(tmp_path, name):
    """A new git repository with the folder results/<name>/: (repo, folder)."""
    repo = tmp_path / "repo"
    folder = repo / "results" / name
    folder.mkdir(parents=True)
    _git(repo, "init", "-q")
    _git(repo, "config", "user.email", "t@example.com")
    _git(repo, "config", "user.name", "t")
    return repo, folder


@pytest.fixture
def plan_repo(tmp_path):
    repo, folder = _repo(tmp_path, "confirm-x")
    (folder / "plan.yaml").write_text(yaml.safe_dump(PLAN))
    _git(repo, "add", ".")
    _git(repo, "commit", "-qm", "plan")
    return repo, folder


def test_the_plan_history_is_checked_from_git(plan_repo):
    repo, folder = plan_repo
    assert check_plan_history(folder) == []
    assert read_plan(folder / "plan.yaml")["draws"] == [0, 1, 2]
    _draw_tables(folder, [0])
    _git(repo, "add", ".")
    _git(repo, "commit", "-qm", "draw 0")
    _draw_tables(folder, [0, 1])
    _git(repo, "commit", "-qam", "draw 1")
    assert check_plan_history(folder) == []
    progress = combine_confirm(folder)
    assert progress["draws_done"] == [0, 1] and progress["status"] == "in progress: 2 of 3 planned draws"
    # a draw dropped after it was committed
    _draw_tables(folder, [1])
    _git(repo, "commit", "-qam", "drop draw 0")
    assert any("draw(s) [0]" in p and "are gone" in p for p in check_plan_history(folder))
    _git(repo, "revert", "--no-edit", "HEAD")
    # a draw the plan does not list
    _draw_tables(folder, [0, 1, 7])
    with pytest.raises(DataError, match=r"draws \[7\] are not in the plan's draws"):
        combine_confirm(folder)
    _git(repo, "checkout", "--", ".")
    # the plan edited in the working tree, then committed
    (folder / "plan.yaml").write_text(yaml.safe_dump(PLAN | {"draws": [0, 1, 2, 3]}))
    assert any("differs from its committed text" in p for p in check_plan_history(folder))
    _git(repo, "commit", "-qam", "edit the plan")
    assert any("changed after its first commit" in p for p in check_plan_history(folder))


def test_a_plan_committed_with_or_after_its_data_is_refused(tmp_path):
    repo, folder = _repo(tmp_path, "confirm-y")
    _draw_tables(folder, [0])
    (folder / "plan.yaml").write_text(yaml.safe_dump(PLAN))
    _git(repo, "add", ".")
    _git(repo, "commit", "-qm", "plan and data at once")
    assert any("committed in or before the plan's commit" in p for p in check_plan_history(folder))
    (tmp_path / "loose").mkdir()
    (tmp_path / "loose" / "plan.yaml").write_text(json.dumps({"format": "x"}))
    with pytest.raises(DataError, match="the plan lacks question"):
        read_plan(tmp_path / "loose" / "plan.yaml")


def test_the_study_runs_only_from_a_committed_plan_and_only_its_draws(plan_repo, tmp_path):
    """`graspaug study confirm` checks the plan's history and the draws asked for before any work."""
    from graspaug.pipeline.studies import confirm as study

    repo, folder = plan_repo
    with pytest.raises(DataError, match=r"--draws \[99\]: not in the plan's draws \[0, 1, 2\]"):
        study.run(repo, folder / "plan.yaml", tmp_path / "work", [99], None, 1, False, "test")
    (folder / "plan.yaml").write_text(yaml.safe_dump(PLAN | {"seeds": [0, 1]}))
    with pytest.raises(DataError, match="differs from its committed text"):
        study.run(repo, folder / "plan.yaml", tmp_path / "work", None, None, 1, False, "test")
    assert not (tmp_path / "work").exists()  # nothing cloned, nothing run


def test_graspaug_results_check_reads_the_plans_history(plan_repo):
    """`graspaug results --check` recomputes the confirmatory folder's figures and fails once its plan is edited."""
    from typer.testing import CliRunner

    from graspaug.pipeline.cli import app

    repo, _ = plan_repo
    (repo / "docs").mkdir()
    text = "<!-- results:confirm-x/status -->in progress: 0 of 3 planned draws\n"
    (repo / "README.md").write_text(text)
    (repo / "docs/results.md").write_text(text)
    ok = CliRunner().invoke(app, ["results", "--root", str(repo), "--check", "--out", str(repo / "out")])
    assert ok.exit_code == 0, ok.output
    (repo / "results/confirm-x/plan.yaml").write_text(yaml.safe_dump(PLAN | {"alpha": 0.1}))
    _git(repo, "commit", "-qam", "a looser alpha")
    edited = CliRunner().invoke(app, ["results", "--root", str(repo), "--check", "--out", str(repo / "out")])
    assert edited.exit_code == 2 and "changed after its first commit" in edited.output


def test_a_plans_words_print_the_level_its_alpha_gives(tmp_path):
    """An alpha of 0.10 gives 90% intervals: words labelled "(95%, ..." are refused; ``{level}`` says 90%."""
    values = {d: {"none@50": 0.5, "none@150": 0.6 + 0.01 * d, "targeted@50": 0.55 + 0.005 * d, "random@50": 0.5}
              for d in range(3)}  # fmt: skip
    loose = PLAN | {"alpha": 0.1}
    loose["words"] = PLAN["words"] | {"raises": "raises AP by {mean} [{low}, {high}] ({level}, {draws} draws)"}
    result = read_plan_result(loose, values)
    assert result["primary"]["verdict"] == "raises" and "(90%, 3 draws)" in result["sentence"]
    assert result["primary"]["high"] - result["primary"]["low"] < read_plan_result(PLAN, values)["primary"]["high"] - \
        read_plan_result(PLAN, values)["primary"]["low"]  # fmt: skip
    (tmp_path / "plan.yaml").write_text(yaml.safe_dump(loose | {"words": PLAN["words"] | {"raises": "up (95%, {p})"}}))
    with pytest.raises(DataError, match=r"words.raises labels its interval \(95%, but alpha 0.1 gives 90% intervals"):
        read_plan(tmp_path / "plan.yaml")
    (tmp_path / "plan.yaml").write_text(yaml.safe_dump(PLAN | {"words": PLAN["words"] | {"raises": "up (95%, {p})"}}))
    assert read_plan(tmp_path / "plan.yaml")["alpha"] == 0.05


def test_a_malformed_or_binary_plan_is_refused_in_one_line(tmp_path):
    """`graspaug study confirm --plan` on broken YAML, a binary file or a YAML list: exit 2, naming the file."""
    from typer.testing import CliRunner

    from graspaug.pipeline.cli import app

    broken, binary, listed = tmp_path / "broken.yaml", tmp_path / "model.pt", tmp_path / "list.yaml"
    broken.write_text("format: graspaug.confirm-plan/1\narms: {none@50: [targeted, 50\n")
    binary.write_bytes(bytes(range(256)) * 4)
    listed.write_text("- a\n- b\n")
    for plan, says in ((broken, "not valid YAML at line"), (binary, "not a text file"), (listed, "it holds a list")):
        with pytest.raises(DataError, match=says):
            read_plan(plan)
        out = CliRunner().invoke(app, ["study", "confirm", "--plan", str(plan), "--project", str(tmp_path)])
        assert out.exit_code == 2, out.output
        assert says in out.output and str(plan.name) in out.output and "bug" not in out.output, out.output


def test_a_deleted_draw_file_is_named_with_its_draw(plan_repo):
    """`graspaug results --check` once a done draw's table is deleted: exit 2, one line naming the draw and the file
    that is gone and how to restore it."""
    from typer.testing import CliRunner

    from graspaug.pipeline.cli import app

    repo, folder = plan_repo
    _draw_tables(folder, [0, 1, 2])  # every planned draw done, and its test and predictions tables gone
    with pytest.raises(DataError, match=r"draw 0's test-d0.parquet is gone \(networks.parquet holds the draw\)"):
        combine_confirm(folder)
    checked = CliRunner().invoke(app, ["results", "--root", str(repo), "--check", "--out", str(repo / "out")])
    line = checked.output.strip()
    assert checked.exit_code == 2 and "\n" not in line, checked.output
    assert "draw 0's test-d0.parquet is gone" in line and "git checkout -- " in line
