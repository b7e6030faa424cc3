"""Dex-Net 2.0 style depth images of grasps: cameras, stable poses, ray-cast crops, gripper collisions.

Frames: the table frame has z up and the table surface at z = 0 (meters). Cameras follow the
OpenCV convention (x right, y down, z along the optical axis); a pixel's integer coordinates
(u = column, v = row) are its center. Depth everywhere is the camera-frame z (meters), as a
depth camera reports it, not the distance along the ray.
"""
