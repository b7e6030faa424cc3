"""Real pybullet: the hand the cell executes is the gripper the grasps are labelled for, and an object collides
where the camera sees it."""

from __future__ import annotations

import dataclasses

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
