"""Shared by the robot-cell studies: the ``sim`` params with changes given on the command line."""

from __future__ import annotations

import dataclasses

import yaml


def with_changes(sim, changes: list[str]):
    """``sim`` (SimParams) with ``section.key=value`` changes (values in YAML), e.g. ``hand.grip_force=20``."""
    sections: dict[str, dict] = {}
    for change in changes:
        key, value = change.split("=", 1)
        section, name = key.split(".", 1)
        sections.setdefault(section, {})[name] = yaml.safe_load(value)
    return dataclasses.replace(sim, **{s: dataclasses.replace(getattr(sim, s), **v) for s, v in sections.items()})
