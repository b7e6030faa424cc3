"""``graspaug evaluate``'s report: the models' test AP and their paired differences, in a table and in words, and what
shaped the test set."""

from __future__ import annotations

from graspaug.experiments.stats import interval_text, verdict

SIZE_WORDS = {
    "real": "at real size",
    "fit": "at real size, those too wide for the gripper scaled down until they fit",
}


#: What a paired difference of two single networks is, in the report and the printed lines: never a method's gain.
SINGLE = "these two networks on these objects; training seeds not covered: not evidence about the method"
#: What a paired difference of one replicate of two arms is (``--seeds``: the same draw and training seed in both).
REPLICATE = "one replicate, the same draw and training seed in both arms: not evidence about the method alone"
#: Replicates an arm needs for a verdict about a method (``--seeds K``).
MIN_REPLICATES = 3
NO_POSITIVE = "n/a (no positive datapoint: AP is undefined)"


def rules_source(params_file, rules: dict | None) -> str:
    """Where the rules that made a test set came from, in words (evaluate.json's ``shaped_by.rules``)."""
    if params_file is not None:
        return f"--params {params_file}"
    if rules:
        return "the models' cards (the rules their training data were made by)"
    return "the built-in defaults (the models' cards hold no test-set rules)"


def ap_text(c: dict, objects: int, spec: str = "+.4f") -> str:
    """A contrast of :func:`~graspaug.experiments.evaluate.numbers.test_ap` as ``mean [low, high]``, with one
    object ``mean (one object: no interval)``, and with no mean (no positive datapoint) :data:`NO_POSITIVE`."""
    if c.get("mean") is None:
        return NO_POSITIVE
    if objects == 1:
        return f"{format(c['mean'], spec)} (one object: no interval)"
    return interval_text(c, spec)


def replicates(result: dict) -> int:
    """How many replicates each arm of an evaluate ``result`` has (seeds of one draw, or networks of as many draws);
    0 without ``--seeds``."""
    first = next(iter(result.get("networks", {}).values()), None)
    return 0 if first is None else int(first["n_seeds"] * first["n_draws"])


def method_verdict(c: dict, n: int) -> str:
    """A replicated difference's verdict (:func:`~graspaug.experiments.stats.verdict`), given only with at least
    :data:`MIN_REPLICATES` replicates an arm."""
    if n < MIN_REPLICATES:
        return f"no verdict: {n} replicates an arm (a method verdict needs --seeds {MIN_REPLICATES} or more)"
    return verdict(c)


def shaped_by_text(shaped_by: dict, counts: dict) -> str:
    """One paragraph: the params, recipe fingerprint, label threshold, size rule and the objects fitted (how many, by
    what scale) behind a test set (``shaped_by``: the ``shaped_by`` of evaluate.json)."""
    params = shaped_by["params"]
    params = params if shaped_by["params_sha256"] is None else f"{params} (sha256 {shaped_by['params_sha256'][:12]})"
    if shaped_by["params_sha256"] is None and shaped_by.get("rules"):  # no --params: the cards' rules, or the defaults
        params = shaped_by["rules"]
    fitted = ""
    if shaped_by["size"] == "fit":
        scale = shaped_by["fit_scale"]
        by = f", scaled by {scale[0]:.3g}–{scale[1]:.3g}" if scale else ""
        fitted = f"; {shaped_by['fitted']} of {counts['shapes']} objects fitted to the gripper{by}"
    return (
        f"Test set shaped by: params {params}, recipe {shaped_by['recipe']}; label: robust ε > "
        f"{shaped_by['label_threshold']:g}; size rule `{shaped_by['size']}` (max width {shaped_by['max_width']:g} m, "
        f"unit scale {shaped_by['unit_scale']:g} m per file unit){fitted}."
    )


def table(head: list[str], rows: dict, cells) -> list[str]:
    """A markdown table's lines: the header ``head``, then one row per ``rows`` item, its name and ``cells(value)``."""
    return [
        "| " + " | ".join(head) + " |",
        "|" + "---|" * len(head),
        *("| " + " | ".join([name, *cells(c)]) + " |" for name, c in rows.items()),
    ]


def report_markdown(result: dict, corpus: str, counts: dict, camera: str, shaped_by: dict) -> str:
    """report.md of :func:`graspaug.experiments.evaluate.numbers.test_ap`'s ``result`` on the test set of folder
    ``corpus`` (``counts``: :func:`graspaug.experiments.evaluate.testset.build_test_set`'s), rendered for ``camera``,
    made as ``shaped_by`` says (:func:`shaped_by_text`)."""
    objects = result["objects"]
    over = (
        "one object: no interval (resampling one object gives its AP every time)"
        if objects == 1
        else f"Intervals: 95% percentile bootstrap over the {objects} objects (every datapoint of a drawn object comes "
        "along); the differences are paired, over the same datapoints and resamples"
    )
    lines = [
        f"# Test AP on {corpus}",
        "",
        f"{counts['files']} files: {counts['shapes']} objects ingested {SIZE_WORDS[counts.get('size', 'real')]} "
        f"({counts['rejected']} rejected, "
        f"see rejects.csv), {counts['with_datapoints']} with datapoints; {result['datapoints']} datapoints, "
        f"{result['positives']} positive ({result['positives'] / max(result['datapoints'], 1):.1%}), rendered for "
        f"{camera}. {over}.",
        "",
        shaped_by_text(shaped_by, counts),
        "",
        *table(
            ["model", "test AP [95% interval over objects]"], result["models"], lambda c: [ap_text(c, objects, ".4f")]
        ),
    ]
    if result["differences"]:
        what = REPLICATE if result.get("networks") else SINGLE
        lines += [
            "",
            *table(
                ["difference", "AP [95% interval over objects]", "what it is"],
                result["differences"],
                lambda c: [ap_text(c, objects), what],
            ),
        ]
    lines += [
        "",
        "The interval covers these objects' resampling only, not another draw of objects of the same kind nor "
        "other training seeds of the models.",
    ]
    if result.get("networks"):
        n, over = replicates(result), result.get("replicates", "seeds")
        what = "training seeds of one draw of the data" if over == "seeds" else "networks of distinct draws of the data"
        lines += [
            "",
            f"The models as arms of {n} replicates each (`--seeds {n}`; their cards say they are {what}): each arm's "
            f"mean test AP, and each arm's paired difference to the first (replicate k with replicate k), 95% over "
            f"the {over} (t on {n - 1} degrees of freedom) and the objects (their bootstrap's variance), added in "
            "quadrature"
            + (
                " (an interval that left AP's range is clipped to it: [0, 1] for a mean AP, [−1, 1] for a difference; "
                "that drops only values AP cannot take, so its coverage is unchanged). "
                if any(c.get("clipped") for c in _arm_contrasts(result))
                else ". "
            )
            + (
                "Over seeds of one draw, a verdict covers that draw of the training data only."
                if over == "seeds"
                else "Over draws, a verdict covers draws of the training data too."
            ),
            "",
            *table(
                ["arm", f"mean test AP [95% over {over} and objects]"],
                result["networks"],
                lambda c: [interval_text(c, ".4f")],
            ),
        ]
        if result["network_differences"]:
            lines += [
                "",
                *table(
                    ["difference", f"AP [95% over {over} and objects]", "verdict about the method"],
                    result["network_differences"],
                    lambda c: [interval_text(c), method_verdict(c, n)],
                ),
            ]
    return "\n".join(lines) + "\n"


def _arm_contrasts(result: dict) -> list[dict]:
    """Every arm's mean and every arms' difference of an evaluate ``result`` with ``--seeds``."""
    return [*result.get("networks", {}).values(), *result.get("network_differences", {}).values()]


def printed_lines(result: dict, report) -> list[str]:
    """What ``graspaug evaluate`` prints: each model's test AP, each single-network difference as what it is
    (:data:`SINGLE`), each arm's mean and difference with ``--seeds``, and where the ``report`` is."""
    objects = result["objects"]
    lines = [f"{name}: test AP {ap_text(c, objects, '.4f')}" for name, c in result["models"].items()]
    what = REPLICATE if result.get("networks") else SINGLE
    lines += [f"{name}: {ap_text(c, objects)} ({what})" for name, c in result["differences"].items()]
    clipped = " (clipped to [0, 1])"
    lines += [
        f"{name}: mean test AP {interval_text(c, '.4f')}{clipped if c.get('clipped') else ''}"
        for name, c in result.get("networks", {}).items()
    ]
    n = replicates(result)
    differences = result.get("network_differences", {})
    lines += [f"{name}: {interval_text(c)} ({method_verdict(c, n)})" for name, c in differences.items()]
    return lines + [f"({objects} objects, {result['datapoints']} datapoints; wrote {report})"]
