"""``graspaug evaluate``'s report: the models' test AP and their paired differences, in a table and in words."""

from __future__ import annotations

from graspaug.experiments.stats import interval_text, verdict

SIZE_WORDS = {
    "real": "at real size",
    "fit": "at real size, those too wide for the gripper scaled down until they fit",
}


def report_markdown(result: dict, corpus: str, counts: dict, camera: str) -> str:
    """report.md of :func:`graspaug.experiments.evaluate.numbers.test_ap`'s ``result`` on the test set of folder
    ``corpus`` (``counts``: :func:`graspaug.experiments.evaluate.testset.build_test_set`'s), rendered for ``camera``."""
    lines = [
        f"# Test AP on {corpus}",
        "",
        f"{counts['files']} files: {counts['shapes']} objects ingested {SIZE_WORDS[counts.get('size', 'real')]} "
        f"({counts['rejected']} rejected, "
        f"see rejects.csv), {counts['with_datapoints']} with datapoints; {result['datapoints']} datapoints, "
        f"{result['positives']} positive ({result['positives'] / max(result['datapoints'], 1):.1%}), rendered for "
        f"{camera}. Intervals: 95% percentile bootstrap over the {result['objects']} objects (every datapoint of a "
        "drawn object comes along); the differences are paired, over the same datapoints and resamples.",
        "",
        "| model | test AP [95% interval over objects] |",
        "|---|---|",
        *(f"| {name} | {interval_text(c, '.4f')} |" for name, c in result["models"].items()),
    ]
    if result["differences"]:
        lines += ["", "| difference | AP [95% interval over objects] | verdict |", "|---|---|---|"]
        lines += [f"| {name} | {interval_text(c)} | {verdict(c)} |" for name, c in result["differences"].items()]
    lines += [
        "",
        "The interval covers these objects' resampling only, not another draw of objects of the same kind nor "
        "other training seeds of the models.",
    ]
    return "\n".join(lines) + "\n"
