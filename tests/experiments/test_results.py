"""Results as data (issue #58): the studies' per-network tables in results/ recompute every figure the README and
docs/results.md quote."""

import json
import re
from pathlib import Path

from typer.testing import CliRunner

from graspaug.experiments.ap.attribution import combine_draws
from graspaug.experiments.results import (
    DOCUMENTS,
    attribution_figures,
    check_markdown,
    combine_attribution,
    marked_figures,
    recompute,
    write_attribution,
)
from graspaug.experiments.stats import interval_text
from graspaug.pipeline.cli import app
from tests.experiments.test_attribution import GENERATE, GQCNN, LABELS, OBJECTS, make_draws

ROOT = Path(__file__).resolve().parents[2]
META = {"command": "graspaug study attribution --draws 0 1", "commit": "0" * 40, "date": "2026-11-28"}


def _results(tmp_path, real_noise=0.1):
    draws = make_draws(tmp_path / "networks", draws=(0, 1, 2), seeds=(0, 1, 2), real_noise=real_noise)
    result = combine_draws(draws, LABELS, OBJECTS, GENERATE, GQCNN, n_resamples=200, seed=3)
    folder = tmp_path / "repo" / "results" / "attribution"
    write_attribution(folder, draws, LABELS, OBJECTS, GENERATE, GQCNN, META | {"n_resamples": 200, "seed": 3})
    return result, folder


def test_the_results_tables_recompute_the_studys_result_figure_for_figure(tmp_path):
    result, folder = _results(tmp_path)
    assert json.loads((folder / "meta.json").read_text())["commit"] == "0" * 40  # the code that made them
    again = combine_attribution(folder)
    assert again["contrasts"] == result["contrasts"] and again["shares"] == result["shares"]
    figures = attribution_figures(result)
    assert figures["attribution/share/recon@10"] == "+100% [+100%, +100%]"  # the real gain is clear here
    assert figures["attribution/worth/recon@10"] == "+10 [+10, +10]"  # its 10 shapes at 1:1 are worth 10 real ones
    curve = result["real_curve"]  # 10 real shapes (the floor), 20: the base set of 20 and 10 + 10 of the real pool
    assert list(curve) == ["10", "20"] and curve["10"]["gain"] is None
    assert curve["20"]["networks"] == ["real/10-1", "targeted/20-0"] and curve["20"]["replicates_sd"] > 0
    assert figures["attribution/real_curve/20"] == interval_text(curve["20"]["gain"])
    real = result["shares"]["recon"]["10"]["real_gain"]
    assert (
        figures["attribution/real_gain@10"]
        == f"{real['mean']:+.4f} [{real['draws_low']:+.4f}, {real['draws_high']:+.4f}]"
    )
    assert recompute(folder.parent)[0] == figures


def test_a_marked_figure_that_differs_or_that_no_study_recomputes_is_named(tmp_path):
    figures = {"attribution/targeted_vs_none@10": "+0.0100 [+0.0010, +0.0210]"}
    good = "gain <!-- results:attribution/targeted_vs_none@10 -->+0.0100 [+0.0010, +0.0210] at B = 10"
    assert check_markdown(good, figures, "README.md") == []
    bad = good.replace("+0.0210]", "+0.0200]") + " and <!-- results:attribution/share/targeted@10 -->+78%"
    problems = check_markdown(bad, figures, "README.md")
    assert problems == [
        "README.md: attribution/targeted_vs_none@10: quoted '+0.0100 [+0.0010, +0.0200]', "
        "recomputed '+0.0100 [+0.0010, +0.0210]'",
        "README.md: attribution/share/targeted@10: no study in results/ recomputes it",
    ]


def test_a_malformed_marker_an_unknown_key_or_a_figure_that_goes_on_is_a_problem():
    """Issue #67: `results --check` skipped a marker written with a space and matched by prefix."""
    figures = {"fidelity/gso300/meshed": "49 of 62"}
    assert check_markdown("| <!-- results:fidelity/gso300/meshed -->49 of 62 |", figures, "README.md") == []
    assert check_markdown("meshed <!-- results:fidelity/gso300/meshed -->49 of 62.", figures, "README.md") == []
    assert check_markdown("<!-- results:fidelity/gso300/meshed -->49 of 620 |", figures, "README.md") == [
        "README.md: fidelity/gso300/meshed: quoted '49 of 620', recomputed '49 of 62'"
    ]
    spaced = "<!-- results:fidelity/gso300/meshed -->49 of 62 and <!-- results: fidelity/gso300/meshed -->49 of 62"
    assert check_markdown(spaced, figures, "README.md") == [
        "README.md: malformed marker '<!-- results: fidelity/gso300/meshed -->' (write `<!-- results:KEY -->`, KEY "
        "of letters, digits, @./+-_)"
    ]
    assert check_markdown("<!-- results:fidelity/gso100/meshed -->49 of 62", figures, "README.md") == [
        "README.md: fidelity/gso100/meshed: no study in results/ recomputes it"
    ]
    assert check_markdown("no marker", figures, "docs/results.md") == [
        "docs/results.md: no marked figure (a `<!-- results:KEY -->` before each quoted figure)"
    ]


def test_graspaug_results_recomputes_and_checks_the_documents(tmp_path):
    result, folder = _results(tmp_path)
    repo = folder.parents[1]
    quoted = attribution_figures(result)["attribution/targeted_vs_blend@10"]
    (repo / "docs").mkdir()
    (repo / "docs/results.md").write_text("nothing marked\n")
    (repo / "README.md").write_text(f"<!-- results:attribution/targeted_vs_blend@10 -->{quoted}\n")
    unmarked = CliRunner().invoke(app, ["results", "--root", str(repo), "--check"])  # a document without a marker
    assert unmarked.exit_code == 2 and "docs/results.md: no marked figure" in unmarked.output
    (repo / "docs/results.md").write_text(f"the same: <!-- results:attribution/targeted_vs_blend@10 -->{quoted}.\n")
    ok = CliRunner().invoke(app, ["results", "--root", str(repo), "--check"])
    assert ok.exit_code == 0, ok.output
    assert f"attribution/targeted_vs_blend@10: {quoted}" in ok.output
    written = json.loads((repo / "reports/results/attribution/figures.json").read_text())
    assert written["attribution/targeted_vs_blend@10"] == quoted
    assert "## What to add" in (repo / "reports/results/attribution/decomposition.md").read_text()
    (repo / "README.md").write_text("<!-- results:attribution/targeted_vs_blend@10 -->+0.5000 [+0.4000, +0.6000]\n")
    bad = CliRunner().invoke(app, ["results", "--root", str(repo), "--check"])
    assert bad.exit_code == 2 and "attribution/targeted_vs_blend@10" in bad.output


def test_the_readme_and_results_quote_only_what_the_committed_results_recompute():
    """Every marked figure of the README and docs/results.md equals what `graspaug results` recomputes from the
    committed results/; and the README's Results section quotes no share of the real-shape gain and no interval
    outside a marked figure (the 2026-11-27 study's per-network results were not kept: it is no longer quoted)."""
    figures, _ = recompute(ROOT / "results")
    for doc in DOCUMENTS:
        assert check_markdown((ROOT / doc).read_text(), figures, doc) == []
    readme = (ROOT / "README.md").read_text()
    results = readme.split("## Results", 1)[1].split("\n## ", 1)[0]
    unmarked = results
    for key, at in marked_figures(results):  # take out every marked figure: what is left quotes no interval
        unmarked = unmarked.replace(results[at - len(f"<!-- results:{key} -->") : at] + figures[key], "", 1)
    shares = re.findall(r"[+−-]?\d+% \[[+−-]?\d+%, [+−-]?\d+%\]", unmarked)  # e.g. "+78% [+1%, +200%]"
    assert shares == [], f"the README quotes shares no committed result recomputes: {shares}"
    loose = re.findall(r"\[[+−-]?\d+\.\d+%?, [+−-]?\d+\.\d+%?\]", unmarked)  # e.g. "[+0.015, +0.043]"
    assert loose == [], f"the README's Results quote intervals no committed result recomputes: {loose}"


def test_the_lifelong_tables_recompute_every_rounds_figures(tmp_path):
    import numpy as np

    from graspaug.experiments.lifelong.numbers import arm_contrasts
    from graspaug.experiments.results import combine_lifelong, lifelong_figures, write_lifelong

    rng = np.random.default_rng(4)
    objects = np.repeat([f"o{i}" for i in range(30)], 8)
    labels = rng.integers(0, 2, size=len(objects))
    skill = {"none": 0.5, "failure": 0.7, "random": 0.6, "real": 1.5}
    networks = {}
    for d in (0, 1):
        for s in (0, 1):
            for arm, k in skill.items():
                folder = tmp_path / f"d{d}" / f"s{s}" / arm
                folder.mkdir(parents=True)
                p = 1 / (1 + np.exp(-(k * (2 * labels - 1) + rng.normal(size=len(labels)))))
                np.save(folder / "test_predictions.npy", p.astype(np.float32))
                networks.setdefault(d, {}).setdefault(s, {})[arm] = folder
    rounds = {0: {d: {s: {"none": a["none"]} for s, a in by.items()} for d, by in networks.items()}, 1: networks}
    study = {k: arm_contrasts(n, labels, objects, 200, 7) for k, n in rounds.items()}
    folder = tmp_path / "results" / "lifelong"
    write_lifelong(folder, rounds, labels, objects, META | {"n_resamples": 200, "seed": 7})
    again = combine_lifelong(folder)
    assert again == study  # float32 predictions, as the networks saved them: figure for figure
    figures = lifelong_figures(study)
    assert figures["lifelong/r1/share"].endswith("]") and "lifelong/r0/ap/none" in figures
    assert recompute(tmp_path / "results")[0] == figures


def test_held_out_fidelity_runs_are_kept_per_autoencoder_and_recompute_their_figures(tmp_path):
    """Two AutoEncoders' per-shape tables in one results/fidelity-<label>/ folder; a rerun of one replaces its rows;
    the figures are the study's summary (heldout_summary), key by key."""
    import numpy as np
    import pandas as pd

    from graspaug.experiments.fidelity.numbers import heldout_summary
    from graspaug.experiments.results import combine_fidelity, fidelity_figures, write_fidelity

    rng = np.random.default_rng(0)

    def per_shape(n, keep):
        before = rng.uniform(0.05, 0.2, n)
        points = rng.integers(50, 120, n).astype(float)
        return pd.DataFrame(
            {
                "shape_id": [f"s{i}" for i in range(n)],
                "meshed": [True] * (n - 1) + [False],
                "graspness_before": before,
                "graspness_after": before * keep + rng.normal(0, 0.01, n),
                "datapoints_before": points,
                "datapoints_after": points * keep,
                "positives_before": points * 0.1,
                "positives_after": points * keep * 0.1,
                **{
                    f"{k}_{w}": rng.uniform(2, 6, n)
                    for k in ("stable_poses", "grasps_rendered")
                    for w in ("before", "after")
                },
            }
        )

    folder = tmp_path / "results" / "fidelity-real"
    first, second = per_shape(20, 0.9), per_shape(20, 0.6)
    write_fidelity(folder, "own", per_shape(20, 0.5), META)
    write_fidelity(folder, "own", first, META)  # a rerun replaces the AutoEncoder's rows
    write_fidelity(folder, "default", second, META)
    result = combine_fidelity(folder)
    assert set(result) == {"own", "default"} and result["own"] == heldout_summary(first)
    assert json.loads((folder / "meta.json").read_text())["runs"]["own"] == META
    figures = fidelity_figures(result, "fidelity-real")
    assert figures["fidelity-real/own/meshed"] == "19 of 20"
    assert figures["fidelity-real/own/datapoints_kept"].startswith("90.0% [")
    assert re.match(r"60\.0% \[", figures["fidelity-real/default/datapoints_kept"])
    assert figures == recompute(tmp_path / "results")[0]


def test_draws_added_one_at_a_time_combine_as_the_whole_study_and_other_params_are_refused(tmp_path):
    """Each finished draw is written at once (a study that stops keeps it); the folder then combines as if every draw
    had been written together, and a draw run with other params is refused, naming the key."""
    from types import SimpleNamespace

    import pytest

    from graspaug.errors import DataError
    from graspaug.experiments.results import add_attribution_draw

    result, _ = _results(tmp_path)
    draws = make_draws(tmp_path / "again", draws=(0, 1, 2), seeds=(0, 1, 2), real_noise=0.1)  # the same (seeded)
    folder = tmp_path / "stepwise" / "attribution"
    meta = META | {"n_resamples": 200, "seed": 3}
    for d in reversed(list(draws)):  # in any order
        add_attribution_draw(folder, d, draws[d], LABELS, OBJECTS, GENERATE, GQCNN, meta | {"seconds": 10 + d})
        assert sorted(json.loads((folder / "meta.json").read_text())["draws"]) >= [str(d)]
    again = combine_attribution(folder)
    assert again["contrasts"] == result["contrasts"] and again["shares"] == result["shares"]
    first = sorted(draws)[0]
    assert combine_attribution(folder, [first])["draws"] == [first]
    with pytest.raises(DataError, match="no draw 99"):
        combine_attribution(folder, [first, 99])
    other = SimpleNamespace(**vars(GQCNN) | {"pools": ("targeted",)})
    with pytest.raises(DataError, match="pools"):
        add_attribution_draw(folder, first, draws[first], LABELS, OBJECTS, GENERATE, other, meta)
    steps = {"gqcnn": {"train": {"max_steps": 1000}}, "render": {"images_per_pose": 5}}
    again = tmp_path / "steps" / "attribution"
    add_attribution_draw(again, 0, draws[0], LABELS, OBJECTS, GENERATE, GQCNN, meta | {"params": steps})
    longer = {"gqcnn": {"train": {"max_steps": 4000}}, "render": {"images_per_pose": 5}}
    with pytest.raises(DataError, match="gqcnn.train.max_steps = 1000, draw 1 with 4000"):
        add_attribution_draw(again, 1, draws[1], LABELS, OBJECTS, GENERATE, GQCNN, meta | {"params": longer})
