"""The model card: what a GQ-CNN was trained for and how well it did (``card`` in ``model.pt``)."""

from __future__ import annotations

from dataclasses import asdict, dataclass, field
from typing import Any

from graspaug.grasping.gripper import ParallelJawGripper
from graspaug.render.settings import CropGeometry, Intrinsics

_INTRINSICS_KEYS = ("width", "height", "fx", "fy", "cx", "cy")


def _default_intrinsics() -> dict:
    return {k: getattr(Intrinsics(), k) for k in _INTRINSICS_KEYS}


@dataclass(frozen=True)
class ModelCard:
    """What a GQ-CNN was trained for and how well it did (``card`` in ``model.pt``).

    ``intrinsics`` (px) and ``camera_distance`` (m, the camera's distance to the table along
    its axis) are the training camera; ``crop_size`` → ``out_size`` (px) the crops; ``gripper``
    the hand (m); ``label_threshold`` the robust ε above which a training grasp counted as a
    success; ``training_set`` its pool, base size, ratio, seed, size, members and training
    precision (None where not recorded); ``validation_ap`` / ``test_ap`` its Average Precision.
    ``operating_point`` (:func:`~graspaug.io.checkpoints.operating_point`) is the threshold on
    P(success) chosen on the validation predictions, the planner's default quality floor;
    ``training_range`` (:func:`~graspaug.io.checkpoints.training_range`) the gripper depths (m) and
    object heights above the table (m) of the training crops. Both are None on cards written before
    they were recorded (format ``graspaug.gqcnn-card/1``). ``assumed`` is True for a checkpoint
    without a card (written before cards existed): the
    defaults are then assumed.
    """

    crop_size: int = 96
    out_size: int = 32
    intrinsics: dict = field(default_factory=_default_intrinsics)
    camera_distance: tuple[float, float] = (0.65, 0.75)
    camera_tilt_deg: tuple[float, float] = (0.1, 5.0)
    gripper: dict = field(default_factory=lambda: asdict(ParallelJawGripper()))
    label_threshold: float | None = None
    training_set: dict = field(default_factory=dict)
    validation_ap: float | None = None
    test_ap: float | None = None
    operating_point: dict | None = None
    training_range: dict | None = None
    image_input: str = "depth"
    graspaug_version: str | None = None
    global_seed: int | None = None
    format: str = "graspaug.gqcnn-card/1"
    assumed: bool = False

    @classmethod
    def from_dict(cls, card: dict[str, Any] | None, image_input: str = "depth") -> ModelCard:
        """The card stored in a checkpoint (None: the defaults, ``assumed``)."""
        if card is None:
            return cls(image_input=image_input, assumed=True)
        known = {k: v for k, v in card.items() if k in cls.__dataclass_fields__}
        for key in ("camera_distance", "camera_tilt_deg"):
            if key in known:
                known[key] = tuple(float(x) for x in known[key])
        return cls(**{**known, "image_input": image_input})

    def to_dict(self) -> dict[str, Any]:
        out = asdict(self)
        out["camera_distance"], out["camera_tilt_deg"] = list(self.camera_distance), list(self.camera_tilt_deg)
        return out

    @property
    def geometry(self) -> CropGeometry:
        return CropGeometry(crop_size=self.crop_size, out_size=self.out_size)

    @property
    def focal_length(self) -> float:
        """Training focal length (px), the mean of fx and fy."""
        return 0.5 * (float(self.intrinsics["fx"]) + float(self.intrinsics["fy"]))
