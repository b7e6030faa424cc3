"""The Franka Emika Panda of ``pybullet_data`` (``franka_panda/panda.urdf``) as a pick-and-place arm.

Joints 0–6 are the arm, 9 and 10 the two fingers (prismatic, 0–0.04 m each, held centered by a
gear constraint), link 11 ``panda_grasptarget`` is the grasp center between the fingertips
(the point every grasp in the project is planned for). Motions are joint-space position control
toward inverse-kinematics targets along straight Cartesian lines, stepped at the simulation's
rate; nothing is teleported once an object is in contact.
"""

from __future__ import annotations

import numpy as np
import pybullet
import pybullet_data

from graspaug.sim.settings import HandSettings

ARM_JOINTS = tuple(range(7))
FINGER_JOINTS = (9, 10)
GRASP_TARGET_LINK = 11
LOWER_LIMITS = np.array([-2.9671, -1.8326, -2.9671, -3.1416, -2.9671, -0.0873, -2.9671])
UPPER_LIMITS = np.array([2.9671, 1.8326, 2.9671, 0.0, 2.9671, 3.8223, 2.9671])
ARM_EFFORT = np.array([87.0, 87.0, 87.0, 87.0, 12.0, 12.0, 12.0])  # N m, the URDF's limits
REST_POSE = np.array([0.0, -0.6, 0.0, -2.4, 0.0, 1.8, 0.785])  # arm folded back, hand down (rad)
FINGER_OPEN = 0.04  # each finger's travel at full opening (m): 0.08 m between the jaws


class Panda:
    """A Panda fixed at ``base_position`` (m) in pybullet client ``client``."""

    def __init__(
        self, client: int, base_position, hand: HandSettings = HandSettings(), time_step: float = 1 / 240
    ) -> None:
        self.client, self.hand, self.time_step = client, hand, time_step
        self.body = pybullet.loadURDF(
            f"{pybullet_data.getDataPath()}/franka_panda/panda.urdf",
            basePosition=list(base_position),
            useFixedBase=True,
            flags=pybullet.URDF_USE_SELF_COLLISION_EXCLUDE_PARENT,
            physicsClientId=client,
        )
        gear = pybullet.createConstraint(
            self.body,
            FINGER_JOINTS[0],
            self.body,
            FINGER_JOINTS[1],
            pybullet.JOINT_GEAR,
            [1, 0, 0],
            [0, 0, 0],
            [0, 0, 0],
            physicsClientId=client,
        )
        pybullet.changeConstraint(gear, gearRatio=-1, erp=0.1, maxForce=hand.centering_force, physicsClientId=client)
        for link in FINGER_JOINTS:
            pybullet.changeDynamics(
                self.body,
                link,
                lateralFriction=hand.finger_friction,
                spinningFriction=hand.finger_spinning_friction,
                physicsClientId=client,
            )
        self.finger_target = FINGER_OPEN
        self.reset(REST_POSE)

    # --- state -------------------------------------------------------------------------------
    def reset(self, arm: np.ndarray, fingers: float = FINGER_OPEN) -> None:
        """Put the arm at joint angles ``arm`` (7,) rad and the fingers at ``fingers`` m at once
        (only before anything is grasped) and hold them there."""
        for joint, angle in zip(ARM_JOINTS, arm):
            pybullet.resetJointState(self.body, joint, float(angle), physicsClientId=self.client)
        for joint in FINGER_JOINTS:
            pybullet.resetJointState(self.body, joint, fingers, physicsClientId=self.client)
        self.finger_target = fingers
        self._command(np.asarray(arm, dtype=float))

    def arm_angles(self) -> np.ndarray:
        return np.array([s[0] for s in pybullet.getJointStates(self.body, ARM_JOINTS, physicsClientId=self.client)])

    def grasp_pose(self) -> tuple[np.ndarray, np.ndarray]:
        """Position (3,) m and quaternion (x, y, z, w) of the grasp center link."""
        state = pybullet.getLinkState(
            self.body, GRASP_TARGET_LINK, computeForwardKinematics=True, physicsClientId=self.client
        )
        return np.array(state[4]), np.array(state[5])

    # --- kinematics --------------------------------------------------------------------------
    @staticmethod
    def top_down(jaw_angle: float) -> list[float]:
        """The hand's quaternion (x, y, z, w) for a straight-down approach with the jaw axis (the
        hand's y axis) at ``jaw_angle`` (rad) from the table's x axis, in the table plane."""
        return list(pybullet.getQuaternionFromEuler([np.pi, 0.0, jaw_angle - np.pi / 2]))

    def inverse_kinematics(self, position, orientation) -> np.ndarray:
        """Arm angles (7,) that put the grasp center at ``position`` (3,) m with ``orientation``
        (pybullet's damped least squares from the current angles, null space toward the rest pose)."""
        angles = pybullet.calculateInverseKinematics(
            self.body,
            GRASP_TARGET_LINK,
            list(position),
            orientation,
            lowerLimits=LOWER_LIMITS.tolist(),
            upperLimits=UPPER_LIMITS.tolist(),
            jointRanges=(UPPER_LIMITS - LOWER_LIMITS).tolist(),
            restPoses=REST_POSE.tolist(),
            maxNumIterations=100,
            residualThreshold=1e-5,
            physicsClientId=self.client,
        )
        return np.array(angles[:7])

    # --- motion ------------------------------------------------------------------------------
    def _command(self, arm: np.ndarray) -> None:
        pybullet.setJointMotorControlArray(
            self.body,
            ARM_JOINTS,
            pybullet.POSITION_CONTROL,
            targetPositions=arm.tolist(),
            forces=ARM_EFFORT.tolist(),
            physicsClientId=self.client,
        )
        pybullet.setJointMotorControlArray(
            self.body,
            FINGER_JOINTS,
            pybullet.POSITION_CONTROL,
            targetPositions=[self.finger_target] * 2,
            forces=[self.hand.grip_force] * 2,
            physicsClientId=self.client,
        )

    def step(self, n: int, arm: np.ndarray | None = None) -> None:
        arm = self.arm_angles() if arm is None else arm
        self._command(arm)
        for _ in range(n):
            pybullet.stepSimulation(physicsClientId=self.client)

    def contact_force(self) -> float:
        """Total normal force (N) of the robot's contacts with other bodies now."""
        return float(
            sum(
                c[9]
                for c in pybullet.getContactPoints(bodyA=self.body, physicsClientId=self.client)
                if c[2] != self.body
            )
        )

    def move_line(
        self, target, jaw_angle: float, speed: float | None = None, settle: float = 0.1, max_force: float | None = None
    ) -> float:
        """Move the grasp center in a straight line to ``target`` (3,) m at ``speed`` m/s, the hand
        pointing down at ``jaw_angle``, then hold the last target for ``settle`` s. With
        ``max_force`` (N) the robot's contacts with other bodies are watched and the motion stops
        at the first step where they press harder; returns the largest contact force seen (N),
        0 when not watched."""
        start, _ = self.grasp_pose()
        target = np.asarray(target, dtype=float)
        orientation = self.top_down(jaw_angle)
        distance = float(np.linalg.norm(target - start))
        steps = max(1, int(np.ceil(distance / (speed or self.hand.speed) / self.time_step)))
        largest = 0.0

        def advance(arm: np.ndarray) -> bool:  # one step toward ``arm``; False once the contacts press too hard
            nonlocal largest
            self._command(arm)
            pybullet.stepSimulation(physicsClientId=self.client)
            if max_force is not None:
                largest = max(largest, self.contact_force())
            return max_force is None or largest <= max_force

        for i in range(1, steps + 1):
            if not advance(self.inverse_kinematics(start + (target - start) * i / steps, orientation)):
                return largest
        arm = self.inverse_kinematics(target, orientation)
        for _ in range(int(round(settle / self.time_step))):
            if not advance(arm):
                break
        return largest

    def set_fingers(self, gap: float) -> None:
        """Drive the fingers toward a jaw gap of ``gap`` m for the hand's close time."""
        self.finger_target = float(np.clip(gap / 2, 0.0, FINGER_OPEN))
        self.step(int(self.hand.close_time / self.time_step))
