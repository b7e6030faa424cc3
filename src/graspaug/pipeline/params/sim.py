"""The ``sim`` section: simulated Panda pick-and-place trials."""

from __future__ import annotations

from graspaug.planning.settings import CEMSettings, SamplerSettings
from graspaug.settings import Field, settings
from graspaug.sim.catalog import EVERYDAY_OBJECTS
from graspaug.sim.settings import CellLayout, DepthNoise, HandSettings, ObjectPhysics, TrialSettings


@settings
class SimParams:
    """Simulated Panda pick-and-place trials: the networks before and after augmentation, the `real` pool's network,
    a random antipodal grasp (the floor) and the best grasp on the true mesh (the oracle: the ceiling) (paper Section
    IV-E)."""

    objects: tuple[str, ...] = Field(
        tuple(EVERYDAY_OBJECTS),
        description=f"Everyday objects of pybullet_data to pick (any of {', '.join(EVERYDAY_OBJECTS)}).",
    )
    n_test_objects: int = Field(
        4, ge=0, description="Held-out test shapes (test split of data/shapes, a seeded choice) picked as well."
    )
    objects_path: str | None = Field(
        None,
        description="A folder of mesh files (.obj, .stl, .ply; one object each, named by file stem) picked as well, "
        "loaded and scaled as the corpus's shapes (ingest.surface); a broken mesh is skipped with its reason logged. "
        "Relative to the project or absolute; DVC tracks this value, not the folder's files.",
    )
    attempts: int = Field(
        1,
        ge=1,
        description="Attempts per object and arm (paper: 10); each attempt drops the object anew from a seeded pose, "
        "the same for every arm. Paired attempts per network arm = objects × attempts × training seeds. (The default "
        "spends the make repro budget on `calibration_grasps` instead, whose paired contrasts need far fewer grasps "
        "than picks do.)",
    )
    base_size: int = Field(
        50,
        ge=2,
        description="Base size B of the networks compared: B-0 (before) and B at the ratio chosen on validation AP "
        "(after, and the `real` pool's network at that ratio); one of gqcnn.augment_base_sizes.",
    )
    calibration_grasps: int = Field(
        500,
        ge=2,
        description="Labelled grasps of the rendered test split (half positive, spread over the test shapes) that the "
        "`grasp_calibration` stage executes in the cell, each shape in its datapoint's stable pose. The `sim` stage "
        "has every arm's networks rank these grasps' outcomes (the `ranking_*` contrasts).",
    )
    n_bootstrap: int = Field(
        2000, ge=100, description="Bootstrap resamples of the objects for the contrasts' 95% intervals."
    )
    n_pictures: int = Field(
        3,
        ge=0,
        description="Trials per arm (first attempts of the first objects) drawn with their depth image, grasp and "
        "pick frames.",
    )
    vhacd_resolution: int = Field(
        4_000_000,
        ge=10000,
        le=64_000_000,
        description="V-HACD voxel resolution of the convex decompositions (cached per mesh in ~/.cache/graspaug/sim "
        "or $GRASPAUG_CACHE). 4e6 keeps the hulls within ~0.3 mm of the mesh the camera sees (1e5: ~1.3 mm) at "
        "~5-12 s an object, once.",
    )
    physics: ObjectPhysics = Field(
        default_factory=ObjectPhysics,
        description="Mass and friction of each object, drawn per object from the global seed.",
    )
    sensor: DepthNoise = Field(
        default_factory=DepthNoise,
        description="The overhead depth sensor's noise, modelled on a RealSense D435 at 0.65 m.",
    )
    cell: CellLayout = Field(
        default_factory=CellLayout, description="The cell: table, robot, bin, overhead camera, physics step."
    )
    hand: HandSettings = Field(default_factory=HandSettings, description="How the hand moves and holds.")
    trial: TrialSettings = Field(default_factory=TrialSettings, description="The pick-and-place motion script.")
    sampler: SamplerSettings = Field(
        default_factory=SamplerSettings, description="Antipodal grasp seeds on the depth image."
    )
    cem: CEMSettings = Field(
        default_factory=CEMSettings, description="Cross-entropy refinement of the seeds by the GQ-CNN."
    )

    def __post_init__(self) -> None:
        unknown = [name for name in self.objects if name not in EVERYDAY_OBJECTS]
        if unknown or len(set(self.objects)) != len(self.objects):
            raise ValueError(
                f"sim.objects: must be distinct names among {', '.join(EVERYDAY_OBJECTS)}; got {list(self.objects)}"
            )
        if not self.objects and self.n_test_objects == 0 and self.objects_path is None:
            raise ValueError(
                "sim.objects: no objects to pick (sim.objects is empty, sim.n_test_objects is 0 and no "
                "sim.objects_path)"
            )
