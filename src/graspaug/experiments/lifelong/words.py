"""The lifelong loop in words: a round's report.md."""

from __future__ import annotations

import pandas as pd

from graspaug.experiments.stats import (
    interval_text,
    share_text,
    verdict,
)


def _table(frame: pd.DataFrame) -> str:
    """A markdown table of ``frame``'s columns (missing values: n/a)."""
    cells = [[("n/a" if pd.isna(v) else str(v)) for v in row] for row in frame.itertuples(index=False)]
    head = [f"| {' | '.join(map(str, frame.columns))} |", "|" + "---|" * len(frame.columns)]
    return "\n".join(head + [f"| {' | '.join(row)} |" for row in cells])


def round_markdown(
    round_: int, result: dict, followed: pd.DataFrame | None, persistent: pd.DataFrame, words: dict
) -> str:
    """A round's report: each arm's test AP, the contrasts with their verdicts (scoped to the draws of the data
    in ``result``: :func:`~graspaug.experiments.stats.draw_verdict`), the share of the real shapes' gain,
    the last round's failures before and after (``followed``; None in round 0), the objects chosen most often
    (``persistent``: :func:`persistent_failures`) and ``words`` (``design``, ``command``)."""
    lines = [f"# Lifelong loop, round {round_}", "", words["design"], ""]
    lines += ["| arm | test AP |", "|---|---|"]
    lines += [f"| {arm} | {interval_text(ap, '.4f')} |" for arm, ap in result["ap"].items()]
    if result["contrasts"]:
        lines += ["", "| contrast | mean [95% interval] | verdict |", "|---|---|---|"]
        for name, c in result["contrasts"].items():
            word = verdict(c)
            lines.append(f"| `{name}@r{round_}` | {interval_text(c)} | {word} |")
    if "share" in result:
        real, failure = result["contrasts"].get("real_data"), result["contrasts"].get("failure_vs_none")
        lines += [
            "",
            "Share of the real shapes' gain that failure-targeted shapes give: "
            f"{share_text(result['share'])} (95% interval by test inversion; unbounded when the real shapes' gain is "
            f"not clearly nonzero), beside its denominator, the real shapes' gain `real_data` {interval_text(real)} "
            f"AP ({verdict(real)}), and failure-targeted shapes' own gain `failure_vs_none` {interval_text(failure)} "
            f"AP ({verdict(failure)}).",
        ]
    if followed is not None:
        lines += [
            "",
            "The last round's failure objects (validation), before and now, per arm:",
            "",
            _table(followed.round(4).reset_index()),
        ]
    lines += [
        "",
        "Objects chosen as failures most often (validation):",
        "",
        _table(persistent.head(10)),
    ]
    return "\n".join(lines + ["", f"Command: `{words['command']}`", ""])
