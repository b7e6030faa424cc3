"""Settings of the simulated cell: layout, hand, motion script, depth sensor, object physics (plain data).

The grasp planner's settings (``sim.sampler``, ``sim.cem``) are in :mod:`graspaug.planning.settings`;
the camera pose of a layout is :func:`graspaug.sim.scene.camera_pose`.
"""

from __future__ import annotations

from graspaug.render.settings import Intrinsics
from graspaug.settings import Field, settings


@settings
class CellLayout:
    """Where things stand (m) and how the world steps (params section ``sim.cell``)."""

    camera_height: float = Field(
        0.65, gt=0.1, description="Depth camera height above the table, looking straight down (m; paper: 0.65)."
    )
    intrinsics: Intrinsics = Field(
        default_factory=Intrinsics, description="The overhead depth camera: image size and intrinsics (px)."
    )
    table_size: tuple[float, float] = Field((1.2, 1.2), description="Table top size along x and y (m).")
    table_friction: float = Field(
        0.8, gt=0, description="Lateral friction coefficient of the table (pybullet multiplies it by the object's)."
    )
    robot_base: tuple[float, float, float] = Field(
        (-0.6, 0.0, 0.0), description="Where the Panda's base stands (m, table frame)."
    )
    bin_position: tuple[float, float, float] = Field(
        (-0.25, 0.5, 0.0), description="Where the bin stands (m, table frame)."
    )
    bin_scale: float = Field(0.5, gt=0, description="Scale of pybullet_data's traybox (0.6 × 0.6 × 0.15 m at scale 1).")
    time_step: float = Field(1 / 240, gt=0, description="Simulation time step (s).")
    gravity: float = Field(9.81, gt=0, description="Gravity (m/s²).")

    @property
    def bin_half_extent(self) -> float:
        """Half the inner width of the bin (m)."""
        return 0.29 * self.bin_scale

    @property
    def bin_height(self) -> float:
        """Height of the bin's walls (m)."""
        return 0.15 * self.bin_scale


@settings
class HandSettings:
    """How the hand moves and holds (SI units; params section ``sim.hand``)."""

    grip_force: float = Field(
        70.0,
        gt=0,
        description="Closing force limit per finger motor (N). With both fingers on the object each presses with "
        "this force, so it is the grasp's clamping force (the Franka Hand's 70 N continuous; 140 N peak).",
    )
    finger_friction: float = Field(
        1.0,
        gt=0,
        description="Lateral friction of the finger pads (pybullet multiplies it by the object's: the pad-object "
        "coefficient is the object's friction).",
    )
    finger_spinning_friction: float = Field(
        0.0033,
        ge=0,
        description="Torsional (spinning) friction of the finger pads (m): the friction torque a pad can resist is "
        "this × the object's lateral friction × the normal force (Bullet's combination). "
        "0.0033 = (2/3)·5 mm, a uniformly pressed contact disc of 5 mm radius (a rubber pad on a rigid "
        "object).",
    )
    centering_force: float = Field(
        50.0,
        gt=0,
        description="Force limit of the gear that keeps the two fingers symmetric about the grasp center (N).",
    )
    speed: float = Field(0.25, gt=0, description="Cartesian speed of the grasp center on the way down and up (m/s).")
    transit_speed: float = Field(
        0.5, gt=0, description="Cartesian speed from the rest pose to the pre-grasp pose (m/s)."
    )
    close_time: float = Field(0.5, gt=0, description="Time given to close the fingers (s).")


@settings
class TrialSettings:
    """The motion script (m, s; params section ``sim.trial``)."""

    drop_offset: float = Field(
        0.05,
        ge=0,
        le=0.15,
        description="Objects are dropped up to this far from the table center in x and y, in a random orientation (m).",
    )
    drop_clearance: float = Field(
        0.02, ge=0, description="Gap between the table and the object's lowest point at release (m)."
    )
    settle_time: float = Field(2.0, gt=0, description="At most this long for the object to come to rest (s).")
    pregrasp_height: float = Field(0.15, gt=0, description="Pre-grasp pose above the grasp center (m).")
    lift_height: float = Field(0.2, gt=0, description="Lift after closing (m).")
    carry_height: float = Field(0.25, gt=0, description="Grasp center above the bin floor when released (m).")
    carry_speed: float = Field(0.5, gt=0, description="Carrying speed (m/s).")
    release_time: float = Field(1.0, gt=0, description="Wait after opening, before the bin check (s).")
    position_error: float = Field(
        0.0,
        ge=0,
        description="SD of the error with which the hand reaches a grasp, along each table axis x, y (m): camera-robot "
        "calibration and control error, drawn per attempt from its drop seed (0: the hand goes where the grasp is).",
    )
    angle_error: float = Field(
        0.0, ge=0, description="SD of the error of the jaw angle about the vertical (rad), drawn as position_error."
    )
    shake_acceleration: float = Field(
        0.0,
        ge=0,
        description="An option beyond the paper's test: after the lift, the held object is shaken, loaded along ±x, "
        "±y, ±z in turn with its weight times this (in g), as a hand shaken with this peak acceleration would load "
        "it (0: no shaking, the paper's test). Held by friction alone, an object of mass m and pad friction mu "
        "needs a grip of m g (1 + a) / (2 mu) a finger (each attempt records it as `shake_grip`): at a = 5, mu = "
        "0.3, 70 N holds 0.71 kg.",
    )
    shake_pulse: float = Field(0.25, gt=0, description="Duration of each of the six half-sine shaking pulses (s).")
    collision_force: float = Field(
        10.0,
        gt=0,
        description="A contact of the robot with anything (object, table, obstacle) pressing harder than this (N) "
        "on the way to the grasp, before the fingers close, ends the trial as `collision`.",
    )


@settings
class DepthNoise:
    """The overhead depth sensor, modelled on an Intel RealSense D435 at 0.65 m (params section ``sim.sensor``).

    Axial noise: SD = ``sd_coefficient`` × z² (stereo depth error grows with the square of the
    distance: RMS ≈ z² · subpixel / (focal length · baseline); the D435's 0.08 px subpixel,
    50 mm baseline and 424 px focal length at 848 × 480 give 0.0038 / m), spatially correlated
    over ``correlation_px`` (stereo matching windows). Missing pixels (read as 0, as the camera
    reports them): within ``edge_band_px`` of a depth jump above ``edge_jump`` each pixel is lost
    with probability ``edge_dropout`` (occlusion and matching failure at object borders), and
    pixels of surfaces steeper than ``steep_angle`` to the view ray with probability
    ``steep_dropout``. Depths are rounded to ``quantization`` (the D435's default depth unit: 1 mm).
    """

    enabled: bool = Field(True, description="Add the noise (false: the renderer's exact depth).")
    sd_coefficient: float = Field(
        0.0038, ge=0, description="Noise SD per squared depth (1/m): SD(z) = this × z², with z in m."
    )
    correlation_px: float = Field(
        2.0,
        ge=0,
        description="SD of the Gaussian smoothing of the noise field (px): stereo matching windows correlate "
        "neighbouring pixels (0: independent pixels).",
    )
    edge_jump: float = Field(
        0.005, gt=0, description="A depth difference to a 4-neighbour above this (m) marks a depth edge."
    )
    edge_band_px: int = Field(
        2, ge=0, description="Pixels within this distance of a depth edge (px, both sides) form the edge band."
    )
    edge_dropout: float = Field(0.3, ge=0, le=1, description="Probability that an edge-band pixel is lost (reads 0).")
    steep_angle: float = Field(
        70.0, gt=0, lt=90, description="Surfaces tilted more than this from facing the camera (degrees) are steep."
    )
    steep_dropout: float = Field(
        0.5, ge=0, le=1, description="Probability that a steep-surface pixel (outside the edge band) is lost (reads 0)."
    )
    quantization: float = Field(0.001, ge=0, description="Depth step (m; D435 depth unit 1 mm; 0: none).")


@settings
class ObjectPhysics:
    """Mass and friction of each object, drawn per object from the global seed (params section ``sim.physics``).

    Mass = density × volume (the closed mesh's volume, or its convex hull's for an open mesh),
    clipped to ``mass_range`` (no floor: 1 g to the Panda's 3 kg payload). The default densities span household
    things: foam and hollow plastic toys (~150 kg/m³ over their enclosed volume), packaged food and wood
    (~500-700), to solid plastic and fruit (~900).
    """

    density_range: tuple[float, float] = Field(
        (150.0, 900.0), description="Density drawn uniformly per object (kg/m³)."
    )
    mass_range: tuple[float, float] = Field(
        (0.001, 3.0),
        description="The mass is clipped to this range (kg): density × volume as it is, between 1 g (a guard "
        "against a degenerate mesh, no floor that makes small objects heavier) and the Panda's 3 kg payload.",
    )
    friction_range: tuple[float, float] = Field(
        (0.3, 0.7),
        description="Lateral friction drawn uniformly per object (pybullet multiplies it by the partner's: 1.0 for "
        "the pads, the table's 0.8).",
    )
    spinning_friction: float = Field(
        0.0,
        ge=0,
        description="The object's own torsional friction (m); the pads' is sim.hand.finger_spinning_friction.",
    )
    rolling_friction: float = Field(
        0.0001, ge=0, description="Rolling friction of the object (m): small, so round objects still roll."
    )

    def __post_init__(self) -> None:
        for name in ("density_range", "mass_range", "friction_range"):
            low, high = getattr(self, name)
            if not 0 < low <= high:
                raise ValueError(f"sim.physics.{name}: must be (low, high) with 0 < low <= high; got {[low, high]}")
