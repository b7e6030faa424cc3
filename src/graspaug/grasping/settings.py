"""Settings of the grasping library: antipodal sampling, the wrench model, the robust metric's perturbations."""

from __future__ import annotations

from graspaug.grasping.gripper import ParallelJawGripper
from graspaug.settings import Field, settings


@settings
class AntipodalSettings:
    """How grasps are sampled; see the module docstring."""

    n_grasps: int = Field(100, ge=1, description="Grasps sampled per shape (Dex-Net 2.0: up to 100; EGAD: 100).")
    friction_coef: float = Field(
        0.5, gt=0, le=1, description="Friction coefficient of the antipodality test (Dex-Net: 0.5)."
    )
    tries_per_point: int = Field(2, ge=1, description="Grasp axes drawn per sampled surface point (Dex-Net: 2).")
    oversample: int = Field(
        5, ge=1, description="Candidates per missing grasp in the first round; doubles each round (Dex-Net: 5)."
    )
    max_rounds: int = Field(5, ge=1, le=10, description="Sampling rounds before giving up on a shape (Dex-Net: 5-10).")
    max_surface_points: int = Field(100, ge=1, description="Surface points sampled per round at most (Dex-Net: 100).")
    min_contact_dist: float = Field(
        0.0025, ge=0, description="Contacts closer than this (m) are rejected (Dex-Net: 2.5 mm)."
    )
    coverage_dist: float = Field(
        0.0025,
        ge=0,
        description="Grasp centers closer than this (m) to a kept one are dropped (EGAD: 2.5 mm; 0 disables).",
    )


@settings
class QualitySettings:
    """The wrench-space model: friction coefficient μ, cone faces, torque scaling s (1/m)."""

    friction_coef: float = Field(
        0.5,
        gt=0,
        le=1,
        description=(
            "Friction coefficient μ of the grasp wrench model (Dex-Net: 0.5); also the mean of the perturbed μ."
        ),
    )
    cone_faces: int = Field(8, ge=3, le=32, description="Faces of the polyhedral friction cone (Dex-Net: 8).")
    torque_scaling: float = Field(
        1000.0,
        gt=0,
        description=(
            "s in the wrench [f; s·τ] (1/m). With s = 1000, soft fingers bound ε by π r² μ s = 0.039 and 0.002 splits "
            "grasps as in Dex-Net 2.0."
        ),
    )


@settings
class Perturbations:
    """Gaussian noise of the robust metric: grasp center (m), grasp axis rotation (rad),
    object translation (m) and rotation (rad), and the friction coefficient's std (its mean
    is ``QualitySettings.friction_coef``; samples are truncated to [0, 1])."""

    n_samples: int = Field(25, ge=1, description="Perturbed samples per grasp in the robust metric (Dex-Net: 25).")
    center_sigma: float = Field(0.005, ge=0, description="Std of the grasp center perturbation in m.")
    axis_sigma: float = Field(0.001, ge=0, description="Std of the grasp axis rotation in rad.")
    object_translation_sigma: float = Field(0.01, ge=0, description="Std of the object translation in m.")
    object_rotation_sigma: float = Field(0.01, ge=0, description="Std of the object rotation in rad.")
    friction_sigma: float = Field(
        0.1, ge=0, description="Std of the perturbed friction coefficient (truncated to [0, 1])."
    )


@settings
class GraspsSettings:
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
