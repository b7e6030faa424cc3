"""The parallel-jaw gripper that every grasp in the project is made for."""
from __future__ import annotations

from dataclasses import dataclass


@dataclass(frozen=True)
class ParallelJawGripper:
    """A two-finger parallel gripper (lengths in meters).

    Defaults are the Franka Emika Panda hand: 0.08 m maximum opening, fingers about 0.02 m wide
    and 0.045 m long. ``finger_radius`` is the radius of the soft-finger contact patch used by
    the torsional friction columns of the grasp wrench (Dex-Net's default 0.005 m).
    """

    name: str = "franka_panda"
    max_width: float = 0.08  # jaw opening (m)
    min_width: float = 0.0  # smallest closing width (m)
    finger_width: float = 0.02  # across the jaw, perpendicular to the grasp axis (m)
    finger_length: float = 0.045  # along the approach direction (m)
    finger_thickness: float = 0.01  # along the grasp axis (m)
    finger_radius: float = 0.005  # soft contact patch radius (m)

    def __post_init__(self) -> None:
        if not 0 <= self.min_width < self.max_width:
            raise ValueError(f"gripper {self.name}: need 0 <= min_width < max_width, got {self.min_width}, {self.max_width}")
        if self.finger_radius < 0:
            raise ValueError(f"gripper {self.name}: finger_radius must be >= 0, got {self.finger_radius}")
