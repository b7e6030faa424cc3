"""Settings classes: frozen dataclasses whose fields carry their default, allowed range and meaning.

Every library settings class (``GQCNNConfig``, ``AntipodalSettings``, ``CellLayout``, …) is
declared with :func:`settings`, so the same class is used three ways: library code builds it
in Python, ``params.yaml`` fills it as a section (pydantic validates types and ranges and
rejects unknown keys), and ``--help`` and ``params.schema.json`` print its field descriptions.
A value is defaulted in exactly one place: its field here.
"""

from __future__ import annotations

import dataclasses
from typing import Any

from pydantic import ConfigDict, Field
from pydantic.dataclasses import dataclass

__all__ = ["Field", "settings", "describe", "is_settings"]

CONFIG = ConfigDict(extra="forbid", validate_by_name=True, validate_by_alias=True)


def settings(cls: type) -> type:
    """Class decorator: a frozen dataclass validated by pydantic; unknown keys are errors."""
    return dataclass(frozen=True, config=CONFIG)(cls)


def is_settings(tp: Any) -> bool:
    return dataclasses.is_dataclass(tp) and hasattr(tp, "__pydantic_fields__")


def _type_name(annotation: Any) -> str:
    text = getattr(annotation, "__name__", None) or str(annotation)
    return text.replace("typing.", "").replace("NoneType", "null")


def describe(cls: type, prefix: str = "") -> str:
    """Markdown list of a settings class's keys (nested sections as ``a.b``), types, defaults and meaning."""
    lines = []
    for name, info in cls.__pydantic_fields__.items():
        key = f"{prefix}{info.alias or name}"
        default = info.get_default(call_default_factory=True)
        if is_settings(type(default)):
            lines.append(describe(type(default), f"{key}."))
            continue
        value = list(default) if isinstance(default, tuple) else default
        lines.append(f"* **{key}** ({_type_name(info.annotation)}, default {value!r}): {info.description or ''}")
    return "\n".join(lines)
