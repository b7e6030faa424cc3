"""The planner's errors: one line each, for bad input (a :class:`~graspaug.errors.DataError`)."""

from __future__ import annotations

from graspaug.errors import DataError


class PlanningError(DataError):
    """Bad input to the planner; ``str(exc)`` is the one-line reason."""


class NoGraspFound(PlanningError):
    """The image holds no antipodal pair of depth edges that fits the gripper."""
