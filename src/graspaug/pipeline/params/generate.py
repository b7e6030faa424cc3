"""The ``generate`` section: the paper's method's own settings (:class:`~graspaug.augment.settings.GenerateSettings`):
new shapes from rare and graspable neighbours of each base set."""

from __future__ import annotations

from graspaug.augment.settings import GenerateSettings as GenerateParams

__all__ = ["GenerateParams"]
