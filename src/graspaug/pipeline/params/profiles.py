"""Profiles: small overlays on the default params, and params.yaml written from them.

A profile file (``profiles/<name>.yaml``) holds only the keys it changes. :func:`apply_profile`
merges it into the defaults (:class:`graspaug.pipeline.params.model.Params`), validates the result and
returns the text of a complete params.yaml, every key commented with its meaning, so that DVC
sees every value and ``dvc params diff`` lines them up.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import yaml

from graspaug.pipeline.params.base import parse_yaml
from graspaug.pipeline.params.model import Params, ParamsError, params_dict, parse_params
from graspaug.pipeline.provenance import fingerprint_line

PROFILES_DIR = Path("profiles")
DEFAULT = "default"


def merge(base: dict, overlay: dict, prefix: str = "") -> dict:
    """``base`` with ``overlay``'s values put in, section by section; an overlay key that is
    not in ``base`` is a :class:`ParamsError` naming it."""
    out = dict(base)
    for key, value in (overlay or {}).items():
        if key not in base:
            raise ParamsError(f"{prefix}{key}: unknown key; allowed here: {', '.join(base)}")
        out[key] = (
            merge(base[key], value, f"{prefix}{key}.")
            if isinstance(base[key], dict) and base[key] and isinstance(value, dict)  # {}: a value (lifelong.rounds)
            else value
        )
    return out


def profile_names(folder: Path = PROFILES_DIR) -> list[str]:
    return [DEFAULT] + sorted(p.stem for p in Path(folder).glob("*.yaml"))


def read_overlay(name: str, folder: Path = PROFILES_DIR) -> dict:
    """The keys profile ``name`` changes (``default``: none)."""
    if name == DEFAULT:
        return {}
    path = Path(folder) / f"{name}.yaml"
    if not path.exists():
        raise ParamsError(f"profile {name!r} not found; known: {', '.join(profile_names(folder))}")
    overlay = parse_yaml(path.read_text(), str(path)) or {}
    if not isinstance(overlay, dict):
        raise ParamsError(f"{path}: expected a mapping of keys")
    return overlay


def profile_params(name: str, folder: Path = PROFILES_DIR) -> Params:
    """The validated params of profile ``name``."""
    try:
        return parse_params(merge(params_dict(), read_overlay(name, folder)))
    except ParamsError as exc:
        raise ParamsError(f"profile {name}: {exc}") from None


def _comments() -> dict[tuple[str, ...], str]:
    """Key path → the first sentence of its description."""
    out: dict[tuple[str, ...], str] = {}

    def walk(cls: Any, path: tuple[str, ...]) -> None:
        fields = getattr(cls, "model_fields", None) or getattr(cls, "__pydantic_fields__", {})
        for name, info in fields.items():
            key = path + (info.alias or name,)
            text = (info.description or "").split(". ")[0].split("\n")[0].rstrip(".")
            out[key] = text if len(text) <= 100 else text[:97] + "..."
            if hasattr(info.annotation, "__pydantic_fields__") or hasattr(info.annotation, "model_fields"):
                walk(info.annotation, key)

    walk(Params, ())
    return out


def _scalar(value: Any) -> str:
    return yaml.safe_dump(value, default_flow_style=True, width=10_000, allow_unicode=True).split("\n")[0]


def params_yaml(params: Params, header: str) -> str:
    """A complete params.yaml for ``params``: every key, each with its meaning as a comment; the ``header`` and the
    values' fingerprint (:func:`~graspaug.pipeline.provenance.fingerprint_line`) on top."""
    comments = _comments()
    lines = ["# yaml-language-server: $schema=params.schema.json"] + [
        f"# {line}".rstrip() for line in header.splitlines()
    ]

    def emit(data: dict, path: tuple[str, ...], indent: str) -> None:
        for key, value in data.items():
            comment = comments.get(path + (key,), "")
            section = isinstance(value, dict) and any(path + (key, k) in comments for k in value)
            if section:  # a settings section; a plain mapping (lifelong.rounds) is a value, written inline
                lines.append(f"{indent}{key}:" + (f"  # {comment}" if comment else ""))
                emit(value, path + (key,), indent + "  ")
            else:
                lines.append(f"{indent}{key}: {_scalar(value)}" + (f"  # {comment}" if comment else ""))

    head, lines[:] = list(lines), []
    emit(params_dict(params), (), "")
    body = "\n".join(lines) + "\n"
    return "\n".join([*head, fingerprint_line(body), body])


def profile_yaml(name: str, folder: Path = PROFILES_DIR) -> str:
    """The text of params.yaml for profile ``name``."""
    header = (
        f"graspaug params, profile `{name}`: written by `graspaug profile {name}` from the defaults"
        + (f" and profiles/{name}.yaml" if name != DEFAULT else "")
        + ".\n"
        "Edit values here (or sweep them with `dvc exp run -S key=value`); `graspaug <stage> --help` explains each key."
    )
    return params_yaml(profile_params(name, folder), header)


def _flat(data: Any, prefix: str = "") -> dict[str, Any]:
    if not isinstance(data, dict) or not data:
        return {prefix.rstrip("."): data}
    return {k: v for key, value in data.items() for k, v in _flat(value, f"{prefix}{key}.").items()}


def hand_edits(text: str, folder: Path = PROFILES_DIR) -> list[str]:
    """The keys of a params.yaml ``text`` whose values no ``graspaug profile`` would write: ``[]`` when ``text`` is
    exactly a profile's file; else each key (``key: value``) that differs from the profile its header names (the
    defaults when it names none or an unknown one), or ``["its text"]`` when only comments or layout differ."""
    import re

    names = profile_names(folder)
    if any(text == profile_yaml(name, folder) for name in names):
        return []
    named = re.search(r"profile `([^`]+)`", text.split("\n", 3)[1] if text.count("\n") > 1 else "")
    name = named.group(1) if named and named.group(1) in names else DEFAULT
    try:
        mine = _flat(parse_yaml(text) or {})
    except ParamsError as exc:
        return [f"its text ({str(exc).removeprefix('params: ')})"]
    theirs = _flat(params_dict(profile_params(name, folder)))
    changed = [f"{k}: {_scalar(v)}" for k, v in mine.items() if k not in theirs or theirs[k] != v]
    return changed + [f"{k} (removed)" for k in theirs if k not in mine] or ["its comments or layout"]


def with_sections(params, sections: dict):
    """``params`` (any stage's params model) with the keys of ``sections`` (section → a mapping of its keys, e.g. a
    model card's ``test_set_rules``: ingest, grasps, render) put over its own, validated again."""
    from graspaug.pipeline.params.base import parse

    raw = params.model_dump(mode="json", by_alias=True)
    for name, values in sections.items():
        raw[name] = (raw.get(name) or {}) | values
    return parse(raw, type(params))
