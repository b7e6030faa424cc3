"""Real pybullet: the hand the cell executes is the gripper the grasps are labelled for, and an object collides
where the camera sees it."""

from __future__ import annotations

import dataclasses
from pathlib import Path

import numpy as np
import pybullet
import pybullet_data
import pytest

from graspaug.grasping.gripper import ParallelJawGripper
from graspaug.sim.panda import FINGER_JOINTS, REST_POSE, probe_hand
from graspaug.sim.scene import PickScene


def test_the_open_hand_is_the_label_gripper_within_half_a_millimetre():
    gripper = ParallelJawGripper()
    with PickScene(gripper=gripper) as scene:
        hand = probe_hand(scene.client, scene.robot.body)
    assert abs(hand["gap"] - gripper.max_width) < 0.0005
    assert abs(hand["tip_depth"] - gripper.fingertip_offset) < 0.0005


def test_a_users_gripper_is_the_hand_that_picks():
    wide = dataclasses.replace(ParallelJawGripper(), name="wide", max_width=0.1, fingertip_offset=0.012)
    with PickScene(gripper=wide) as scene:
        hand = probe_hand(scene.client, scene.robot.body)
    assert abs(hand["gap"] - 0.1) < 0.0005 and abs(hand["tip_depth"] - 0.012) < 0.0005


def test_the_stock_panda_fingers_are_not_the_label_gripper():
    """The probe can fail: pybullet_data's own finger meshes (1 mm collision margin, rounded pads) leave 77.8 mm."""
    client = pybullet.connect(pybullet.DIRECT)
    try:
        body = pybullet.loadURDF(
            f"{pybullet_data.getDataPath()}/franka_panda/panda.urdf", useFixedBase=True, physicsClientId=client
        )
        for joint, angle in enumerate(REST_POSE):
            pybullet.resetJointState(body, joint, angle, physicsClientId=client)
        for joint in FINGER_JOINTS:
            pybullet.resetJointState(body, joint, 0.04, physicsClientId=client)
        hand = probe_hand(client, body)
    finally:
        pybullet.disconnect(client)
    assert hand["gap"] == pytest.approx(0.0778, abs=0.0005)
    assert hand["tip_depth"] > ParallelJawGripper().fingertip_offset + 0.0005


GSO100 = Path(__file__).resolve().parents[2] / ".." / "shared" / "corpora" / "gso100"
HULL_OBJECTS = ("AllergenFree_JarroDophilus",)  # a 5.4 × 5.4 × 9.6 cm bottle: ~5 s of V-HACD


@pytest.fixture(scope="module")
def gso_bodies(sim_cache):
    """gso100 objects at their real size, decomposed at the default resolution: (mesh, SimObject) each."""
    if not GSO100.is_dir():
        pytest.skip(f"{GSO100} is absent")
    from graspaug.geometry.loading import load_shape
    from graspaug.geometry.prepare import prepare_shape
    from graspaug.geometry.settings import SurfaceSettings
    from graspaug.sim.objects import body_origin, prepare_object

    out = []
    for name in HULL_OBJECTS:
        mesh = prepare_shape(load_shape(GSO100 / f"{name}.obj"), SurfaceSettings(size="real")).mesh
        body = prepare_object(name, mesh, sim_cache, mass=0.1, lateral_friction=0.5)
        out.append((mesh.copy().apply_translation(-body_origin(mesh)), body))
    return out


def test_each_collision_shape_lies_within_half_a_millimetre_of_the_mesh(gso_bodies):
    from graspaug.sim.objects import collision_hulls, hull_offset

    for mesh, body in gso_bodies:
        offset = hull_offset(mesh, collision_hulls(body.collision))
        assert offset["median"] < 0.0005 and offset["box"] < 0.0005, (body.name, offset)


def test_a_jaw_feels_the_width_the_camera_sees(gso_bodies):
    """In pybullet (margins included): exact box probes beside the object, along each table axis, find it no
    more than 0.5 mm wider a side than its mesh."""
    for mesh, body in gso_bodies:
        with PickScene() as scene:
            obj = scene.add_object(body, [0.0, 0.0, 0.3], [0, 0, 0, 1])
            for axis in range(3):
                for side in (-1, 1):
                    extent = mesh.bounds[1 if side > 0 else 0][axis]
                    center = np.array([0.0, 0.0, 0.3])
                    center[axis] += extent + side * 0.0105  # a plate 1 mm thick, 1 cm beside the mesh
                    half = [0.2, 0.2, 0.2]
                    half[axis] = 0.0005
                    shape = pybullet.createCollisionShape(
                        pybullet.GEOM_BOX, halfExtents=half, physicsClientId=scene.client
                    )
                    probe = pybullet.createMultiBody(
                        0, shape, basePosition=center.tolist(), physicsClientId=scene.client
                    )
                    distance = min(
                        c[8] for c in pybullet.getClosestPoints(obj, probe, 0.1, physicsClientId=scene.client)
                    )
                    pybullet.removeBody(probe, physicsClientId=scene.client)
                    assert 0.01 - distance < 0.0005, (body.name, axis, side, 0.01 - distance)


def test_a_small_object_weighs_what_its_density_says():
    """No floor: a 2 cm cube of 500 kg/m³ weighs 4 g (the old 0.2 kg floor made it 50 times heavier)."""
    from graspaug.sim.objects import draw_physics
    from graspaug.sim.settings import ObjectPhysics

    drawn = draw_physics(0.02**3, ObjectPhysics(density_range=(500.0, 500.0)), np.random.default_rng(0))
    assert drawn["mass"] == pytest.approx(0.004)
