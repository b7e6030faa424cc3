"""Settings of the depth-image grasp planner: the antipodal sampler and the cross-entropy method."""

from __future__ import annotations

from graspaug.settings import Field, settings


@settings
class SamplerSettings:
    """Dex-Net 2.0's antipodal depth-image sampler (params section ``sim.sampler``)."""

    friction_coef: float = Field(
        0.8, gt=0, description="Friction coefficient of the antipodality test on depth edges (Dex-Net: 0.8)."
    )
    depth_grad_thresh: float = Field(
        0.0025, gt=0, description="Depth gradient (m per px) that marks an edge pixel (Dex-Net: 0.0025)."
    )
    min_dist_from_boundary: int = Field(
        45, ge=0, description="Edge pixels this close to the image border are ignored (px; Dex-Net: 45)."
    )
    min_depth_offset: float = Field(
        0.005, ge=0, description="Grasp depth below the surface between the jaws, lowest (m; Dex-Net: 0.005)."
    )
    max_depth_offset: float = Field(0.04, ge=0, description="... and highest (m; Dex-Net: 0.04).")
    max_width: float = Field(0.08, gt=0, description="Jaw opening (m); must equal grasps.gripper.max_width.")
    max_edge_pixels: int = Field(3000, ge=2, description="Edge pixels kept at random to pair up.")

    def __post_init__(self) -> None:
        if self.min_depth_offset > self.max_depth_offset:
            raise ValueError(
                f"max_depth_offset: must be >= min_depth_offset ({self.min_depth_offset}); got {self.max_depth_offset}"
            )


@settings
class CEMSettings:
    """Cross-entropy refinement, Dex-Net 2.0's (params section ``sim.cem``)."""

    num_seed_samples: int = Field(250, ge=1, description="Antipodal seed grasps per image (Dex-Net: 100-250).")
    num_iters: int = Field(3, ge=0, description="Cross-entropy iterations (Dex-Net: 3).")
    elite_fraction: float = Field(
        0.25, gt=0, le=1, description="Share of the best grasps refit each iteration (Dex-Net: 0.25)."
    )
    gmm_components: int = Field(3, ge=1, description="Gaussian mixture components at most ...")
    gmm_component_fraction: float = Field(
        0.4, gt=0, le=1, description="... or ceil(this × elites) when fewer (Dex-Net: 0.4)."
    )
    num_gmm_samples: int = Field(50, ge=1, description="Grasps drawn from the mixture per iteration (Dex-Net: 50).")
