"""Simulated robot trials: a pybullet Franka Panda picks objects from a table into a bin with
grasps a GQ-CNN plans on an overhead depth image (paper Section IV-E, in simulation)."""
