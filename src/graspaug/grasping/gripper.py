"""The parallel-jaw gripper that every grasp in the project is made for."""

from __future__ import annotations

from graspaug.settings import Field, settings


@settings
class ParallelJawGripper:
    """A two-finger parallel gripper (lengths in meters).

    Defaults are the Franka Emika Panda hand: 0.08 m maximum opening; finger and palm boxes are
    the bounding boxes of the collision meshes in pybullet_data's ``franka_panda`` (the grasp
    center is the URDF's ``panda_grasptarget``, 0.105 m in front of the hand). In the grasp frame
    (x: jaw axis, z: approach) a finger spans z in [fingertip_offset - finger_length,
    fingertip_offset]; the palm spans z in [-palm_offset - palm_size[2], -palm_offset].
    ``finger_radius`` is the radius of the soft-finger contact patch used by the torsional
    friction columns of the grasp wrench (Dex-Net's default 0.005 m).
    """

    name: str = Field("franka_panda", description="Name of the gripper (recorded with the data).")
    max_width: float = Field(0.08, gt=0, description="Jaw opening (m; Franka Panda: 0.08).")
    min_width: float = Field(0.0, ge=0, description="Smallest closing width (m).")
    finger_width: float = Field(
        0.021, gt=0, description="Finger size across the jaw, perpendicular to the grasp axis (m)."
    )
    finger_length: float = Field(0.0538, gt=0, description="Finger size along the approach direction (m).")
    finger_thickness: float = Field(
        0.0264, gt=0, description="Finger size along the grasp axis, outward from the jaw face (m)."
    )
    fingertip_offset: float = Field(0.0072, description="How far the fingertips reach past the grasp center (m).")
    palm_offset: float = Field(0.039, ge=0, description="Distance from the grasp center back to the palm (m).")
    palm_size: tuple[float, float, float] = Field(
        (0.2045, 0.0632, 0.0919), description="Palm box along the axis, across, along the approach (m)."
    )
    finger_radius: float = Field(
        0.005,
        ge=0,
        description="Soft-finger contact radius for the torsion columns of the grasp wrench (m; Dex-Net: 0.005).",
    )

    def __post_init__(self) -> None:
        if not 0 <= self.min_width < self.max_width:
            raise ValueError(
                f"gripper {self.name}: need 0 <= min_width < max_width, got {self.min_width}, {self.max_width}"
            )
        if self.finger_radius < 0:
            raise ValueError(f"gripper {self.name}: finger_radius must be >= 0, got {self.finger_radius}")
