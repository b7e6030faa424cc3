"""Which params and which corpus made a report: the lines every report a stage writes opens with.

The profile is read from the params file itself: ``graspaug profile <name>`` (and a study's params) writes a header
naming the profile and a fingerprint of its values (:func:`values_fingerprint`); a value edited since (by hand, or
``dvc exp run -S``) no longer matches the fingerprint, and the report says so. The corpus is the file's ``data``
section and, where the stage reads it, the shape table's counts. Nothing here imports the params model, so a stage
that writes a report does not depend on every section's settings.
"""

from __future__ import annotations

import hashlib
import json
import re

import pandas as pd
import yaml

#: Profiles whose numbers mean nothing (a smoke test of the pipeline), with the warning their reports carry.
SMOKE_PROFILES = {
    "tiny": "a smoke test of the pipeline (a handful of shapes, 16³ voxels, networks trained for a few steps): "
    "its numbers mean nothing"
}
_PROFILE = re.compile(r"profile `([^`]+)`")
_FINGERPRINT = re.compile(r"^# values sha256 ([0-9a-f]{12})\b", re.MULTILINE)


def values_fingerprint(text: str) -> str:
    """12 hex digits of the sha256 of the values of a params file's ``text`` (comments and layout ignored)."""
    values = json.dumps(yaml.safe_load(text), sort_keys=True, default=str)
    return hashlib.sha256(values.encode()).hexdigest()[:12]


def fingerprint_line(text: str) -> str:
    """The comment line a params file's header carries for its values (:func:`values_fingerprint` of ``text``)."""
    return f"# values sha256 {values_fingerprint(text)} (reports check it: a value edited since is named as edited)"


def profile_words(text: str | None) -> tuple[str | None, str]:
    """The profile a params file's ``text`` names (None: none) and one phrase on where its values come from (edited
    since the profile wrote them, when they no longer match its fingerprint). ``text`` None: params built in code."""
    if text is None:
        return None, "params built in code (no params file)"
    lines = text.splitlines()
    header = "\n".join(lines[: next((i for i, line in enumerate(lines) if not line.startswith("#")), len(lines))])
    named, stamp = _PROFILE.search(header), _FINGERPRINT.search(header)
    if named is None:
        return None, "a params file no `graspaug profile` wrote (its header names no profile)"
    name = named.group(1)
    origin = "the defaults" + ("" if name == "default" else f" + profiles/{name}.yaml")
    if stamp is None or stamp.group(1) != values_fingerprint(text):
        what = (
            "no fingerprint of its values to check them by" if stamp is None else "values edited since it was written"
        )
        return name, f"profile `{name}` ({origin}) with {what} (`graspaug profile {name}` names the edited keys)"
    return name, f"profile `{name}` (params.yaml = {origin})"


def corpus_words(text: str | None, shapes: pd.DataFrame | None = None) -> str:
    """The shape corpus in words: the ``data`` section of a params file's ``text`` (source, folder, limit) and, given
    the shape table ``shapes`` (one row per kept shape, column ``split``), how many shapes were kept per split."""
    data = ((yaml.safe_load(text) or {}).get("data") if text else None) or {}
    source = data.get("source", "pybullet")
    where = "pybullet_data/random_urdfs" if source == "pybullet" else f"the meshes under `{data.get('path')}`"
    limit = data.get("limit")
    words = f"{where}, {'all files' if limit is None else f'the first {limit} files'}"
    if shapes is not None:
        counts = shapes["split"].value_counts()
        words += f"; {len(shapes)} shapes kept ({counts.get('train', 0)} train, {counts.get('test', 0)} test)"
    return words if text else f"{words} (the defaults)"


def report_header(text: str | None, shapes: pd.DataFrame | None = None) -> str:
    """The lines a report opens with (Markdown, a blank line after): the profile and corpus that made it
    (:func:`profile_words`, :func:`corpus_words` of a params file's ``text`` and the shape table ``shapes``), and a
    loud warning when the profile is a smoke test (:data:`SMOKE_PROFILES`)."""
    name, profile = profile_words(text)
    lines = [f"> Made with {profile}; corpus: {corpus_words(text, shapes)}."]
    if name in SMOKE_PROFILES:
        lines += [">", f"> **Profile `{name}` is {SMOKE_PROFILES[name]}.**"]
    return "\n".join(lines) + "\n\n"
