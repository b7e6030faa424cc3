"""Settings of the simulated cell: layout, hand, motion script, grasp planner."""
from __future__ import annotations

import numpy as np

from graspaug.render.camera import CameraPose, Intrinsics, look_at
from graspaug.settings import Field, settings


@settings
class CellLayout:
    """Where things stand (m) and how the world steps (params section ``sim.cell``)."""

    camera_height: float = Field(0.65, gt=0.1, description="Depth camera height above the table, looking straight down (m; paper: 0.65).")
    intrinsics: Intrinsics = Field(default_factory=Intrinsics, description="The overhead depth camera.")
    table_size: tuple[float, float] = Field((1.2, 1.2), description="Table top (m).")
    table_friction: float = Field(0.8, gt=0, description="Lateral friction of the table.")
    robot_base: tuple[float, float, float] = Field((-0.6, 0.0, 0.0), description="Where the Panda's base stands (m, table frame).")
    bin_position: tuple[float, float, float] = Field((-0.25, 0.5, 0.0), description="Where the bin stands (m, table frame).")
    bin_scale: float = Field(0.5, gt=0, description="Scale of pybullet_data's traybox (0.6 × 0.6 × 0.15 m at scale 1).")
    time_step: float = Field(1 / 240, gt=0, description="Simulation time step (s).")
    gravity: float = Field(9.81, gt=0, description="Gravity (m/s²).")

    @property
    def bin_half_extent(self) -> float:
        """Half the inner width of the bin (m)."""
        return 0.29 * self.bin_scale

    @property
    def bin_height(self) -> float:
        return 0.15 * self.bin_scale

    @property
    def camera(self) -> CameraPose:
        return look_at(np.array([0.0, 0.0, self.camera_height]), np.zeros(3))


@settings
class HandSettings:
    """How the hand moves and holds (SI units; params section ``sim.hand``)."""

    grip_force: float = Field(20.0, gt=0, description="Closing force limit per finger (N; the URDF's effort limit is 20).")
    finger_friction: float = Field(1.0, gt=0, description="Lateral friction of the finger pads.")
    speed: float = Field(0.25, gt=0, description="Cartesian speed of the grasp center (m/s).")
    close_time: float = Field(0.5, gt=0, description="Time given to close the fingers (s).")


@settings
class TrialSettings:
    """The motion script (m, s; params section ``sim.trial``)."""

    drop_offset: float = Field(0.05, ge=0, le=0.15, description="Objects are dropped up to this far from the table center in x and y, in a random orientation (m).")
    drop_clearance: float = Field(0.02, ge=0, description="Gap between the table and the object's lowest point at release (m).")
    settle_time: float = Field(2.0, gt=0, description="At most this long for the object to come to rest (s).")
    pregrasp_height: float = Field(0.15, gt=0, description="Pre-grasp pose above the grasp center (m).")
    lift_height: float = Field(0.2, gt=0, description="Lift after closing (m).")
    carry_height: float = Field(0.25, gt=0, description="Grasp center above the bin floor when released (m).")
    carry_speed: float = Field(0.5, gt=0, description="Carrying speed (m/s).")
    release_time: float = Field(1.0, gt=0, description="Wait after opening, before the bin check (s).")


@settings
class SamplerSettings:
    """Dex-Net 2.0's antipodal depth-image sampler (params section ``sim.sampler``)."""

    friction_coef: float = Field(0.8, gt=0, description="Friction coefficient of the antipodality test on depth edges (Dex-Net: 0.8).")
    depth_grad_thresh: float = Field(0.0025, gt=0, description="Depth gradient (m per px) that marks an edge pixel (Dex-Net: 0.0025).")
    min_dist_from_boundary: int = Field(45, ge=0, description="Edge pixels this close to the image border are ignored (px; Dex-Net: 45).")
    min_depth_offset: float = Field(0.005, ge=0, description="Grasp depth below the surface between the jaws, lowest (m; Dex-Net: 0.005).")
    max_depth_offset: float = Field(0.04, ge=0, description="... and highest (m; Dex-Net: 0.04).")
    max_width: float = Field(0.08, gt=0, description="Jaw opening (m); must equal grasps.gripper.max_width.")
    max_edge_pixels: int = Field(3000, ge=2, description="Edge pixels kept at random to pair up.")


@settings
class CEMSettings:
    """Cross-entropy refinement, Dex-Net 2.0's (params section ``sim.cem``)."""

    num_seed_samples: int = Field(250, ge=1, description="Antipodal seed grasps per image (Dex-Net: 100-250).")
    num_iters: int = Field(3, ge=0, description="Cross-entropy iterations (Dex-Net: 3).")
    elite_fraction: float = Field(0.25, gt=0, le=1, description="Share of the best grasps refit each iteration (Dex-Net: 0.25).")
    gmm_components: int = Field(3, ge=1, description="Gaussian mixture components at most ...")
    gmm_component_fraction: float = Field(0.4, gt=0, le=1, description="... or ceil(this × elites) when fewer (Dex-Net: 0.4).")
    num_gmm_samples: int = Field(50, ge=1, description="Grasps drawn from the mixture per iteration (Dex-Net: 50).")
