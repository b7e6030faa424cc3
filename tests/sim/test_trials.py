"""Real pybullet: the cell, the Panda's scripted picks, and one planned pick end to end."""

from __future__ import annotations

import numpy as np
import pybullet
import pytest
import torch

from graspaug.nets.gqcnn import GQCNN, GQCNNConfig
from graspaug.planning import Planner
from graspaug.planning.grasps import ImageGrasps
from graspaug.planning.settings import CEMSettings, SamplerSettings
from graspaug.render.camera import look_at
from graspaug.render.settings import Intrinsics
from graspaug.sim.scene import CellLayout, PickScene, camera_pose
from graspaug.sim.settings import HandSettings, TrialSettings
from graspaug.sim.trials import OUTCOMES, grasp_in_table_frame, run_trial


def top_down_across(position, quaternion):
    """Grasp the resting cube at its center, jaws across the body axis that lies flattest."""
    axes = np.array(pybullet.getMatrixFromQuaternion(quaternion)).reshape(3, 3).T  # rows: body axes in the table frame
    flat = axes[np.argmin(np.abs(axes[:, 2]))]
    return np.asarray(position), float(np.arctan2(flat[1], flat[0]))


def test_the_camera_looks_straight_down_from_its_height():
    camera = camera_pose(CellLayout(camera_height=0.7))
    assert np.isclose(camera.height, 0.7) and np.isclose(camera.tilt, 0.0)
    on_axis = camera.to_table(np.array([[0.0, 0.0, 0.7]]))
    assert np.allclose(on_axis, 0.0, atol=1e-12)  # the optical axis meets the table at the origin


def test_image_grasp_to_table_frame():
    K = Intrinsics()
    camera = look_at(np.array([0.0, 0.0, 0.65]), np.zeros(3))
    point = np.array([[0.05, -0.03, 0.02]])
    uv = K.project(camera.to_camera(point))
    grasps = ImageGrasps(centers=uv, angles=np.array([0.4]), depths=np.array([0.63]), widths=np.array([30.0]))
    centers, angles = grasp_in_table_frame(grasps, camera, K)
    assert np.allclose(centers, point, atol=1e-9)
    # seen from above the image's u axis is the table's x axis and v is -y: image angle a is table angle -a
    assert np.isclose(angles[0], -0.4)


def test_empty_table_depth_is_camera_height_at_center():
    with PickScene() as scene:
        depth = scene.depth_image()
    assert depth.shape == (480, 640)
    assert abs(depth[240, 320] - 0.65) < 1e-4
    # straight down at a flat table, every pixel's z-depth is the height: the robot at rest and
    # the bin stay out of view
    assert np.abs(depth - 0.65).max() < 1e-4


def test_scripted_top_down_cube_grasp_lands_in_bin(cube):
    result = run_trial(cube, drop_seed=3, scripted=top_down_across)
    assert result.outcome == "success" and result.success
    assert 0.0 < result.grasp_center[2] < 0.05  # the cube rests on the table, its center ~2 cm up


def test_the_hand_errs_by_a_seeded_offset(cube):
    """With an execution error the hand misses the planned center by an offset drawn from the drop seed (the
    planned center is what the trial reports); a 10 cm SD puts the jaws far off the cube, which is then not
    lifted or hit, while the same grasp without the error lands it in the bin (above)."""
    sloppy = TrialSettings(position_error=0.1, angle_error=0.2)
    result = run_trial(cube, drop_seed=3, scripted=top_down_across, settings=sloppy)
    again = run_trial(cube, drop_seed=3, scripted=top_down_across, settings=sloppy)
    exact = run_trial(cube, drop_seed=3, scripted=top_down_across)
    assert exact.hand_error == (0.0, 0.0, 0.0) and result.hand_error == again.hand_error
    assert np.hypot(*result.hand_error[:2]) > 0.05  # this seed's draw: beyond the cube's half width
    assert result.grasp_center == exact.grasp_center and result.outcome in ("not_lifted", "collision")


def test_a_blocked_approach_is_a_collision(cube):
    """A plate 10 cm above the table over the drop area: the hand hits it on the way to the cube
    (the same grasp without the plate lands the cube in the bin, above)."""
    plate = ((0.1, 0.1, 0.005), (0.0, 0.0, 0.1))
    result = run_trial(cube, drop_seed=3, scripted=top_down_across, obstacles=(plate,))
    assert result.outcome == "collision" and not result.success
    assert result.contact_force > TrialSettings().collision_force


def test_fingers_into_the_table_are_a_collision(cube):
    def too_low(position, quaternion):
        center, angle = top_down_across(position, quaternion)
        return center - [0.0, 0.0, 0.04], angle

    result = run_trial(cube, drop_seed=3, scripted=too_low)
    assert result.outcome == "collision"
    # what the hand hit is logged with the force of each pair: 4 cm low, the palm lands on the 3.9 cm cube's top
    assert [(link, other) for link, other, _ in result.contacts] == [("panda_hand", "object")]
    assert sum(f for *_, f in result.contacts) == pytest.approx(result.contact_force, abs=1e-2)


def test_user_folder_of_meshes_runs_through_the_trials(tmp_path, sim_cache):
    """Two meshes and a broken file in a folder: the broken one is skipped with its reason, the two
    are scaled like the corpus's shapes, get drawn physics, and each runs one trial."""
    import trimesh

    from graspaug.experiments.cell.trials import ObjectJob, prepare_objects, run_object
    from graspaug.geometry.settings import SurfaceSettings
    from graspaug.sim.objects import folder_meshes
    from graspaug.sim.settings import ObjectPhysics

    trimesh.creation.box(extents=[40.0, 60.0, 30.0]).export(tmp_path / "block.stl")  # any units: scaled like the corpus
    trimesh.creation.cylinder(radius=20.0, height=50.0, sections=24).export(tmp_path / "can.ply")
    (tmp_path / "broken.obj").write_text("v 0 0 0\nthis is not a mesh\n")
    (tmp_path / "notes.txt").write_text("not a mesh file")
    surface = SurfaceSettings()
    meshes, skipped = folder_meshes(tmp_path, surface)
    assert (
        [name for name, _ in meshes] == ["block", "can"] and list(skipped) == ["broken.obj"] and skipped["broken.obj"]
    )
    for _, mesh in meshes:
        assert sorted(mesh.extents)[1] == pytest.approx(
            surface.size_m, rel=0.02
        )  # the middle extent, as ingest sizes shapes
    physics = ObjectPhysics()
    objects = prepare_objects(
        [], [], tmp_path, physics, seed=0, vhacd_resolution=10_000, user_meshes=meshes, cache_dir=sim_cache
    )
    again = prepare_objects(
        [], [], tmp_path, physics, seed=0, vhacd_resolution=10_000, user_meshes=meshes, cache_dir=sim_cache
    )
    assert [o.body.mass for o in objects] == [o.body.mass for o in again]  # drawn from the seed
    for obj in objects:
        assert obj.kind == "user" and physics.mass_range[0] <= obj.body.mass <= physics.mass_range[1]
        assert physics.friction_range[0] <= obj.body.lateral_friction <= physics.friction_range[1]
        job = ObjectJob("antipodal", -1, None, obj.name, obj.kind, obj.body, (3,), (4,), False)
        rows = run_object(
            job,
            layout=CellLayout(),
            hand=HandSettings(),
            sampler=SamplerSettings(),
            cem=CEMSettings(),
            crop_size=96,
            out_size=32,
        )
        assert len(rows) == 1 and rows[0]["outcome"] in OUTCOMES and rows[0]["object"] == obj.name


def test_an_empty_folder_is_a_one_line_error(tmp_path):
    from graspaug.geometry.settings import SurfaceSettings
    from graspaug.sim.objects import folder_meshes

    with pytest.raises(ValueError, match=r"holds no mesh file") as caught:
        folder_meshes(tmp_path, SurfaceSettings())
    assert "\n" not in str(caught.value)
    (tmp_path / "bad.stl").write_text("solid nothing\nendsolid nothing\n")
    with pytest.raises(ValueError, match=r"no usable mesh in .*bad.stl"):
        folder_meshes(tmp_path, SurfaceSettings())


def test_grasp_in_empty_space_fails(cube):
    def beside(position, quaternion):
        return np.asarray(position) + [0.0, 0.15, 0.0], 0.0

    result = run_trial(cube, drop_seed=3, scripted=beside)
    assert result.outcome == "not_lifted" and not result.success


def test_drop_is_seeded_and_object_falls_onto_table(cube):
    a, b, c = (run_trial(cube, drop_seed=s, scripted=top_down_across) for s in (5, 5, 6))
    assert a.drop_position == b.drop_position and a.grasp_center == b.grasp_center
    assert a.drop_position != c.drop_position


def planner_with(net: GQCNN, seed: int):
    """A grasp source as the sim stage builds one: the public planner, Dex-Net's policy (no image check)."""
    planner = Planner(net, cem=CEMSettings(num_seed_samples=100), check_image=False)
    rng = np.random.default_rng(seed)

    def plan(depth, camera, intrinsics):
        return next(iter(planner.plan(depth, intrinsics, rng, camera_distance=camera.height, fill_missing=True)), None)

    return plan


def test_planned_pick_same_seed_same_outcome(duck):
    torch.manual_seed(0)
    net = GQCNN(GQCNNConfig(filters=4, fc=16, pose_fc=4)).eval()
    layout = CellLayout()
    first = run_trial(duck, drop_seed=11, planner=planner_with(net, 7), layout=layout, record=True)
    second = run_trial(duck, drop_seed=11, planner=planner_with(net, 7), layout=layout, record=True)
    assert first.image_grasp is not None and first.quality is not None
    assert first.drop_position == second.drop_position and np.array_equal(
        first.depth, second.depth
    )  # the same noisy image
    assert (first.depth == 0).any()  # the sensor lost pixels (at the duck's edges)
    assert (
        first.outcome == second.outcome
        and first.image_grasp == second.image_grasp
        and first.grasp_center == second.grasp_center
    )
    # the planned grasp lies on the duck: its center pixel sees something above the table
    u, v = round(first.image_grasp["u"]), round(first.image_grasp["v"])
    assert first.depth[v, u] < layout.camera_height - 0.005
    assert [label for label, _ in first.frames] == [
        "object dropped",
        "pre-grasp",
        "closed",
        "lifted",
        "over the bin",
        "released",
    ][: len(first.frames)]
    assert all(frame.shape == (240, 320, 3) for _, frame in first.frames)


def test_jaw_angle_convention_on_a_long_bar(sim_cache):
    """A 3 × 12 × 3 cm bar: closing across its width lifts it, closing along its length (wider than
    the 8 cm opening) cannot: a finger comes down on the bar. A jaw angle off by 90° or a flipped
    axis would swap the outcomes."""
    import trimesh

    from graspaug.sim.objects import prepare_object

    bar = prepare_object(
        "bar", trimesh.creation.box(extents=[0.03, 0.12, 0.03]), sim_cache, mass=0.1, lateral_friction=0.5
    )

    def jaws(axis_index):
        def scripted(position, quaternion):
            axes = (
                np.array(pybullet.getMatrixFromQuaternion(quaternion)).reshape(3, 3).T
            )  # rows: body axes in the table frame
            long_axis = axes[1]  # the bar's 12 cm axis lies flat whatever face it rests on
            across = np.array([-long_axis[1], long_axis[0], 0.0])
            axis = across if axis_index == "across" else long_axis
            return np.asarray(position), float(np.arctan2(axis[1], axis[0]))

        return scripted

    assert run_trial(bar, drop_seed=2, scripted=jaws("across")).outcome == "success"
    assert run_trial(bar, drop_seed=2, scripted=jaws("along")).outcome == "collision"  # a finger lands on the bar's end


def test_shaking_drops_a_grasp_far_from_the_center_of_mass(sim_cache):
    """A 0.3 kg bar (3 × 12 × 3 cm) held with 20 N: grasped across at its middle it survives a 5 g shake (friction
    needs 17.7 N a finger: the attempt states it); grasped 4.5 cm toward one end it is carried to the bin unshaken,
    but the shake twists it out of the pads (the torque about the jaw axis outgrows the pads' friction), as the
    grasp's lower wrench resistance says. Held with 10 N, below the 11.8 N a 3 g shake needs, it slips out."""
    import trimesh

    from graspaug.sim.objects import prepare_object

    bar = prepare_object(
        "heavy-bar", trimesh.creation.box(extents=[0.03, 0.12, 0.03]), sim_cache, mass=0.3, lateral_friction=0.5
    )

    def across(offset):
        def scripted(position, quaternion):
            long_axis = np.array(pybullet.getMatrixFromQuaternion(quaternion)).reshape(3, 3).T[1]
            return np.asarray(position) + offset * long_axis, float(np.arctan2(long_axis[0], -long_axis[1]))

        return scripted

    hand, shaken, still = (
        HandSettings(grip_force=20),
        TrialSettings(shake_acceleration=5),
        TrialSettings(shake_acceleration=0),
    )
    centered = run_trial(bar, drop_seed=2, scripted=across(0.0), hand=hand, settings=shaken)
    assert centered.outcome == "success" and centered.shake_grip == pytest.approx(0.3 * 9.81 * 6 / (2 * 0.5))
    weak, gentle = HandSettings(grip_force=10), TrialSettings(shake_acceleration=3)
    assert run_trial(bar, drop_seed=2, scripted=across(0.0), hand=weak, settings=gentle).outcome == "dropped"
    assert run_trial(bar, drop_seed=2, scripted=across(0.045), hand=hand, settings=still).outcome == "success"
    off_center = run_trial(bar, drop_seed=2, scripted=across(0.045), hand=hand, settings=shaken, record=True)
    assert off_center.outcome == "dropped" and "shaken" in [name for name, _ in off_center.frames]
