"""The confirmatory study's words: the figures a document quotes from a plan's result (:func:`confirm_figures`), each
test as ``mean [low, high], p = P`` (:func:`test_text`)."""

from __future__ import annotations

from collections.abc import Mapping


def sentence_fields(c: Mapping) -> dict:
    """A test's fields as a plan's sentences name them: ``mean``, ``low``, ``high`` (signed), ``p``, ``draws``."""
    return {
        "mean": f"{c['mean']:+.4f}",
        "low": f"{c['low']:+.4f}",
        "high": f"{c['high']:+.4f}",
        "p": f"{c['p']:.3f}" if c["p"] >= 0.001 else f"{c['p']:.1e}",
        "draws": c["n_draws"],
    }


def confirm_figures(result: dict, study: str) -> dict[str, str]:
    """The figures a document quotes, by key: ``<study>/status``, and once complete ``<study>/control``,
    ``<study>/primary`` (``mean [low, high], p = P``), ``<study>/primary/verdict``, ``<study>/sentence``,
    ``<study>/primary/sensitivity`` (exploratory: draws above 0, Wilcoxon, each draw left out),
    ``<study>/<secondary>`` and its ``/verdict`` (and ``/equivalence``: its TOST where the plan names a margin),
    ``<study>/exploratory/<a>-<b>`` (a contrast the plan names as exploratory: no verdict), ``<study>/ap/<arm>``
    (the arm's mean AP over draws), each again for an external test set as ``<study>/<set>/...``,
    ``<study>/worth`` (the exchange rate); with the folder's base-set counts ``<study>/worth/actual`` (the same on
    the objects that hold datapoints), ``<study>/base_objects`` and ``<study>/generator_objects`` (the train objects
    each draw's AutoEncoder-Critic learned)."""
    out = {f"{study}/status": result["status"]}
    if not result["complete"]:
        return out
    for key in ("control", "primary"):
        out[f"{study}/{key}"] = test_text(result[key])
    out[f"{study}/primary/verdict"] = result["primary"]["verdict"]
    if result["primary"].get("sensitivity"):
        out[f"{study}/primary/sensitivity"] = sensitivity_text(result["primary"]["sensitivity"])
    out[f"{study}/control/verdict"] = "shows" if result["control"]["shows"] else "does not show"
    out[f"{study}/sentence"] = result["sentence"]
    for name, c in result["secondary"].items():
        holm = f" (Holm p = {c['p_holm']:.3f})" if c.get("p_holm") is not None else ""
        out[f"{study}/{name}"] = test_text(c) + holm
        if "verdict" in c:
            out[f"{study}/{name}/verdict"] = c["verdict"]
        e = c.get("equivalence") or {}
        if e.get("p") is not None:
            out[f"{study}/{name}/equivalence"] = (
                f"TOST p = {e['p']:.3f}, its {e['level']:.0%} interval [{e['low']:+.4f}, {e['high']:+.4f}] "
                f"against ±{e['margin']:g}"
            )
    out |= _exploratory_and_arms(result, study)
    for name, r in result.get("external", {}).items():
        out[f"{study}/{name}/control"] = test_text(r["control"])
        out[f"{study}/{name}/control/verdict"] = "shows" if r["control"]["shows"] else "does not show"
        out[f"{study}/{name}/primary"] = test_text(r["primary"])
        out[f"{study}/{name}/primary/verdict"] = r["primary"]["verdict"]
        out[f"{study}/{name}/sentence"] = r["sentence"]
        for key, c in r["secondary"].items():
            holm = f" (Holm p = {c['p_holm']:.3f})" if c.get("p_holm") is not None else ""
            out[f"{study}/{name}/{key}"] = test_text(c) + holm
            out[f"{study}/{name}/{key}/verdict"] = c["verdict"]
        out |= _exploratory_and_arms(r, f"{study}/{name}")
    if "exchange" in result:
        e = result["exchange"]
        low = "≤ {}".format(e["sizes"][0]) if e["low"] is None else f"{e['low']:.0f}"
        high = "≥ {}".format(e["sizes"][-1]) if e["high"] is None else f"{e['high']:.0f}"
        worth = f"outside the curve ({e['outside']})" if e["worth"] is None else f"{e['worth']:.0f}"
        out[f"{study}/worth"] = f"{worth} real objects [{low}, {high}]"
    if "exchange_actual" in result:
        e, b = result["exchange_actual"], result["base_objects"]
        low = "≤ {:.0f}".format(e["ends"][0]) if e["low"] is None else f"{e['low']:.0f}"
        high = "≥ {:.0f}".format(e["ends"][1]) if e["high"] is None else f"{e['high']:.0f}"
        worth = f"outside the curve ({e['outside']})" if e["worth"] is None else f"{e['worth']:.0f}"
        out[f"{study}/worth/actual"] = f"{worth} objects holding datapoints [{low}, {high}]"
        out[f"{study}/base_objects"] = f"{b['min']}–{b['max']} (mean {b['mean']:.1f}) of the nominal {b['nominal']}"
        trained = b["train_objects_min"], b["train_objects_max"]
        out[f"{study}/generator_objects"] = f"{trained[0]}" if trained[0] == trained[1] else "{}–{}".format(*trained)
    return out


def _exploratory_and_arms(result: Mapping, prefix: str) -> dict[str, str]:
    """``<prefix>/exploratory/<a>-<b>`` of each exploratory contrast and ``<prefix>/ap/<arm>`` (4 decimals)."""
    out = {f"{prefix}/exploratory/{name}": test_text(c) for name, c in result.get("exploratory", {}).items()}
    return out | {f"{prefix}/ap/{arm}": f"{v:.4f}" for arm, v in result.get("arms", {}).items()}


def test_text(c: Mapping) -> str:
    """``+0.0300 [+0.0100, +0.0500], p = 0.012`` of a :func:`~graspaug.experiments.confirm.numbers.draw_test`."""
    f = sentence_fields(c)
    return f"{f['mean']} [{f['low']}, {f['high']}], p = {f['p']}"


def sensitivity_text(s: Mapping) -> str:
    """``above 0 in 10 of 12 draws; Wilcoxon p = 0.005; each draw left out: p 0.011–0.035`` of a
    :func:`~graspaug.experiments.confirm.numbers.draw_sensitivity`."""
    low, high = s["loo_p"]
    return (
        f"above 0 in {s['positive']} of {s['n_draws']} draws; Wilcoxon p = {s['wilcoxon_p']:.3f}; "
        f"each draw left out: p {low:.3f}–{high:.3f}"
    )
