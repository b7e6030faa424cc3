"""The ``grasps`` section: antipodal grasps on every shape, labelled by robust Ferrari-Canny."""

from __future__ import annotations

from graspaug.grasping.gripper import ParallelJawGripper
from graspaug.grasping.settings import AntipodalSettings, Perturbations, QualitySettings
from graspaug.settings import Field, settings


@settings
class GraspsParams:
    """Antipodal grasps on every shape, labelled by robust Ferrari-Canny (Dex-Net 2.0)."""

    threshold: float = Field(
        0.002,
        ge=0,
        description="A grasp succeeds when its robust ε exceeds this (Dex-Net 2.0, with the torque scaling and "
        "object size of the defaults).",
    )
    gripper: ParallelJawGripper = Field(
        default_factory=ParallelJawGripper, description="The Franka Panda hand every grasp is made for."
    )
    sampler: AntipodalSettings = Field(
        default_factory=AntipodalSettings, description="Antipodal grasp sampling on the mesh."
    )
    quality: QualitySettings = Field(
        default_factory=QualitySettings, description="The grasp wrench model of Ferrari-Canny ε."
    )
    perturbations: Perturbations = Field(
        default_factory=Perturbations, description="The robust metric's perturbations."
    )
