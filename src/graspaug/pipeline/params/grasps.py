"""The ``grasps`` section: the grasping library's own settings (:class:`~graspaug.grasping.settings.GraspsSettings`):
antipodal grasps on every shape, labelled by robust Ferrari-Canny."""

from __future__ import annotations

from graspaug.grasping.settings import GraspsSettings as GraspsParams

__all__ = ["GraspsParams"]
