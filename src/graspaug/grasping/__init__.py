"""Grasp analysis: the parallel-jaw gripper, contacts found by ray casting, Dex-Net's
antipodal sampler, and the robust Ferrari-Canny quality that labels every grasp."""
