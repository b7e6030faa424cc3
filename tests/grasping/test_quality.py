"""Ferrari-Canny ε: hand-computed values, invariances, and agreement of the fast facet search
with qhull and of qhull with independent computations."""

import numpy as np
import pytest
import trimesh
from scipy.optimize import linprog
from scipy.spatial import ConvexHull

from graspaug.grasping.gripper import ParallelJawGripper
from graspaug.grasping.quality import (
    TANGENT_SEARCH_STEPS,
    contact_frames,
    ferrari_canny,
    ferrari_canny_qhull,
    grasp_wrenches,
)
from graspaug.grasping.robust import QualitySettings, grasp_epsilon

QUALITY = QualitySettings(friction_coef=0.5, cone_faces=8, torque_scaling=1000.0)
PANDA = ParallelJawGripper()


def dexnet_tangents(in_normal):
    """Dex-Net's Contact3D.tangents(align_axes=True), transcribed loop for loop."""
    direction = in_normal.reshape((3, 1))
    U, _, _ = np.linalg.svd(direction)
    x, y = U[:, 1], U[:, 2]
    if np.cross(x, y).dot(direction.ravel()) < 0:
        y = -y
    max_ip, max_theta, theta = 0, 0, 0
    target = np.array([1, 0, 0])
    d_theta = 2 * np.pi / float(TANGENT_SEARCH_STEPS)
    for _ in range(TANGENT_SEARCH_STEPS):
        v = np.cos(theta) * x + np.sin(theta) * y
        if v.dot(target) > max_ip:
            max_ip, max_theta = v.dot(target), theta
        theta = theta + d_theta
    v = np.cos(max_theta) * x + np.sin(max_theta) * y
    return v, np.cross(direction.ravel(), v)


def test_contact_frames_are_dexnets():
    rng = np.random.default_rng(0)
    normals = rng.normal(size=(40, 3))
    normals /= np.linalg.norm(normals, axis=1, keepdims=True)
    t1, t2 = contact_frames(normals)
    for n, a, b in zip(normals, t1, t2):
        ref1, ref2 = dexnet_tangents(n)
        np.testing.assert_allclose(a, ref1, atol=1e-12)
        np.testing.assert_allclose(b, ref2, atol=1e-12)
    np.testing.assert_allclose(np.einsum("ij,ij->i", t1, normals), 0, atol=1e-12)
    np.testing.assert_allclose(np.cross(t1, t2), normals, atol=1e-12)


def square_cone_grasp(mu, finger_radius, torque_scaling, half_gap):
    """Two contacts on the z axis at ±half_gap, pushing toward each other, 4-sided cones."""
    p1, p2 = np.array([[0, 0, -half_gap]]), np.array([[0, 0, half_gap]])
    n1, n2 = np.array([[0, 0, -1.0]]), np.array([[0, 0, 1.0]])
    return grasp_wrenches(
        p1, n1, p2, n2, np.array([[0, 0, 1.0]]), np.zeros(3), mu, torque_scaling, finger_radius, cone_faces=4
    )[:2]


@pytest.mark.parametrize("mu", [0.3, 0.5, 0.8])
def test_known_value_worked_by_hand(mu):
    """Contacts at (0, 0, ∓a) with inward normals ±z, 4 cone faces along ±x, ±y (the frames turn
    t1 to x), s·a = 1, soft fingers of radius r.

    Force and torque rows of contact 1 are (g, 1, J g), of contact 2 (g, -1, -J g), for
    g ∈ {±μ e_x, ±μ e_y} and J g = (g_y, -g_x); torsion is ±T e_τz with T = π r² μ s.
    In the orthonormal coordinates (f_x ± τ_y)/√2, (f_y ± τ_x)/√2, f_z, the contact-1 points
    are a diamond of radius b = √2 μ in two coordinates at f_z = 1, the contact-2 points a
    diamond in the other two at f_z = -1. Their hull Q (in τ_z = 0) has support
    h(v) = max(b max(|v2|,|v3|) + v5, b max(|v1|,|v4|) - v5); its minimum over unit v is at
    v2 = v3 = 0, |v1| = |v4| = β, v5 = bβ/2 with β²(2 + b²/4) = 1, so Q's inradius is
    h = b / √(8 + b²) = μ / √(4 + μ²). Adding the apexes ±T e_τz makes a bipyramid whose
    facets through a facet of Q at distance h and an apex are at distance 1/√(1/h² + 1/T²).
    """
    r, s = 0.005, 1000.0
    wrenches, slips = square_cone_grasp(mu, r, s, half_gap=1.0 / s)
    h, t = mu / np.sqrt(4 + mu**2), np.pi * r**2 * mu * s
    expected = 1 / np.sqrt(1 / h**2 + 1 / t**2)
    assert not slips[0]
    assert ferrari_canny_qhull(wrenches[0]) == pytest.approx(expected, rel=1e-9)
    assert ferrari_canny(wrenches)[0] == pytest.approx(expected, rel=1e-9)


def test_hard_fingers_and_missing_contact_give_zero():
    wrenches, _ = square_cone_grasp(0.5, 0.0, 1000.0, 0.001)  # no torsion: flat wrench set
    assert ferrari_canny(wrenches)[0] == 0.0 and ferrari_canny_qhull(wrenches[0]) == 0.0
    with pytest.raises(ValueError, match="inside must be"):
        ferrari_canny(wrenches, np.ones(3, dtype=bool))
    # contact 2 pushed sideways (normal ⟂ push): it contributes nothing
    p1, p2 = np.array([[0, 0, -0.01]]), np.array([[0, 0, 0.01]])
    wrenches, slips, _ = grasp_wrenches(
        p1,
        np.array([[0, 0, -1.0]]),
        p2,
        np.array([[1.0, 0, 0]]),
        np.array([[0, 0, 1.0]]),
        np.zeros(3),
        0.5,
        1000.0,
        0.005,
    )
    assert slips[0]
    assert ferrari_canny(wrenches)[0] == 0.0 and ferrari_canny_qhull(wrenches[0]) == 0.0


def sphere_grasps(offsets):
    """Grasps along x across a 3 cm sphere, shifted sideways by ``offsets`` (m)."""
    mesh = trimesh.creation.icosphere(subdivisions=5, radius=0.03)
    centers = np.stack([np.zeros_like(offsets), offsets, 0.3 * offsets], axis=1)
    axes = np.tile([1.0, 0.0, 0.0], (len(offsets), 1))
    return mesh, centers, axes


def test_zero_outside_force_closure_positive_inside():
    # Sideways offset d tilts both normals by asin(d / 0.03) from the contact line; the cone's
    # half-angle is atan(0.5) = 26.6 deg, reached at d ≈ 0.0134 m.
    offsets = np.array([0.0, 0.004, 0.008, 0.016, 0.02, 0.025])
    mesh, centers, axes = sphere_grasps(offsets)
    eps = grasp_epsilon(mesh, centers, axes, 0.5, PANDA, QUALITY)
    assert np.all(eps[:3] > 0.002)
    assert np.all(eps[3:] == 0.0)
    # the same without the slip shortcut: the hull itself says 0 outside force closure
    from graspaug.grasping.contacts import close_fingers

    c = close_fingers(mesh, centers, axes, PANDA.max_width)
    wrenches, slips, inside = grasp_wrenches(c.p1, c.n1, c.p2, c.n2, axes, mesh.center_mass, 0.5, 1000.0, 0.005)
    assert list(slips) == [False, False, False, True, True, True]
    assert list(inside) == [True, True, True, False, False, False]
    fast = ferrari_canny(wrenches)
    assert np.all(fast[3:] == 0.0) and np.all(fast[:3] > 0)
    assert [ferrari_canny_qhull(w) for w in wrenches[3:]] == [0.0, 0.0, 0.0]


def test_centered_grasps_on_sphere_and_box():
    sphere = trimesh.creation.icosphere(subdivisions=4, radius=0.03)
    box = trimesh.creation.box((0.05, 0.04, 0.06))
    for mesh in (sphere, box):
        axes = np.eye(3)
        eps = grasp_epsilon(mesh, np.zeros((3, 3)), axes, 0.5, PANDA, QUALITY)
        bound = np.pi * 0.005**2 * 0.5 * 1000.0  # soft fingers: ε never exceeds the torsion column
        assert np.all(eps > 0) and np.all(eps <= bound), eps


def random_rotation(rng):
    q, _ = np.linalg.qr(rng.normal(size=(3, 3)))
    return q * np.sign(np.linalg.det(q))


def test_rigid_motion_of_object_and_grasp_keeps_epsilon():
    rng = np.random.default_rng(3)
    mesh = trimesh.creation.box((0.05, 0.03, 0.06))
    mesh.apply_translation([0.004, -0.002, 0.001])
    centers = rng.normal(0, 0.004, (30, 3))
    # Across the y faces (on the x faces the normal is parallel to the x axis that t1 is turned
    # toward, so the cone's orientation is decided by rounding noise), tilted up to ~15 deg
    # from the normals so the contact line stays clear of the 26.6 deg cone's edges.
    axes = rng.normal(size=(30, 3)) * 0.15 + [0, 1.0, 0]
    axes /= np.linalg.norm(axes, axis=1, keepdims=True)
    base = grasp_epsilon(mesh, centers, axes, 0.5, PANDA, QUALITY)
    assert (base > 0).sum() >= 10
    for _ in range(3):
        rot, shift = random_rotation(rng), rng.normal(0, 0.1, 3)
        moved = mesh.copy()
        moved.apply_transform(np.vstack([np.c_[rot, shift], [0, 0, 0, 1]]))
        eps = grasp_epsilon(moved, centers @ rot.T + shift, axes @ rot.T, 0.5, PANDA, QUALITY, x_axis=rot @ [1.0, 0, 0])
        # Dex-Net turns t1 in 2π/1000 steps from an SVD basis that does not move with the
        # object, so the cone may turn by up to 0.0063 rad: ε moves by well under 0.5% when
        # the contact line is not near the cone's boundary (there it can move by ~10%).
        np.testing.assert_allclose(eps, base, rtol=5e-3, atol=1e-12)


def perturbed_grasp_wrenches(n, seed, cone_faces=8):
    """Wrench sets of random grasps on an ellipsoid, a box and a sphere, random μ."""
    rng = np.random.default_rng(seed)
    meshes = [
        trimesh.creation.icosphere(4, 0.03),
        trimesh.creation.box((0.05, 0.04, 0.07)),
        trimesh.creation.icosphere(4, 1.0),
    ]
    meshes[2].apply_scale([0.03, 0.02, 0.04])
    from graspaug.grasping.contacts import close_fingers

    out = []
    for mesh in meshes:
        centers = rng.normal(0, 0.006, (n, 3))
        axes = rng.normal(size=(n, 3))
        axes /= np.linalg.norm(axes, axis=1, keepdims=True)
        c = close_fingers(mesh, centers, axes, 0.08)
        f = c.found
        mu = np.clip(rng.normal(0.5, 0.1, f.sum()), 0, 1)
        w, _, inside = grasp_wrenches(
            c.p1[f], c.n1[f], c.p2[f], c.n2[f], axes[f], mesh.center_mass, mu, 1000.0, 0.005, cone_faces
        )
        out.append((w, inside))
    return np.concatenate([w for w, _ in out]), np.concatenate([i for _, i in out])


def test_fast_epsilon_equals_qhull_on_grasp_wrenches():
    wrenches, inside = perturbed_grasp_wrenches(150, seed=0)
    # symmetric, degenerate ones too: exactly antipodal contacts on the sphere and box faces
    mesh = trimesh.creation.box((0.05, 0.04, 0.07))
    from graspaug.grasping.contacts import close_fingers

    c = close_fingers(mesh, np.zeros((3, 3)), np.eye(3), 0.08)
    sym, _, sym_inside = grasp_wrenches(c.p1, c.n1, c.p2, c.n2, np.eye(3), mesh.center_mass, 0.5, 1000.0, 0.005)
    wrenches, inside = np.concatenate([wrenches, sym]), np.concatenate([inside, sym_inside])
    plain = np.array([ferrari_canny_qhull(w) for w in wrenches])
    assert (plain > 0).mean() > 0.2 and (plain == 0).mean() > 0.1  # both kinds are tested
    # the geometric force-closure test never vouches for a set whose origin is not inside
    assert inside.sum() > 100 and np.all(plain[inside] > 0)
    np.testing.assert_allclose(ferrari_canny(wrenches), plain, rtol=0, atol=1e-9)  # origin checked for every set
    np.testing.assert_allclose(
        ferrari_canny(wrenches, inside), plain, rtol=0, atol=1e-9
    )  # checked where not vouched for


@pytest.mark.parametrize("cone_faces", [3, 5, 12])
def test_fast_epsilon_equals_qhull_for_other_cones(cone_faces):
    wrenches, inside = perturbed_grasp_wrenches(40, seed=cone_faces, cone_faces=cone_faces)
    plain = np.array([ferrari_canny_qhull(w) for w in wrenches])
    assert (plain > 0).sum() > 10
    np.testing.assert_allclose(ferrari_canny(wrenches, inside), plain, rtol=0, atol=1e-9)


def boundary_distance_lp(points, direction):
    """max λ with λ·direction in the convex hull of ``points`` (an LP, HiGHS)."""
    n = len(points)
    a_eq = np.zeros((7, n + 1))
    a_eq[:6, :n], a_eq[:6, n], a_eq[6, :n] = points.T, -direction, 1.0
    lp = linprog(
        c=np.r_[np.zeros(n), -1.0],
        A_eq=a_eq,
        b_eq=np.r_[np.zeros(6), 1.0],
        bounds=[(0, None)] * (n + 1),
        method="highs",
    )
    assert lp.status == 0
    return -lp.fun


def test_epsilon_of_grasp_wrenches_matches_support_function_and_lp():
    """The same independent check on real grasp wrench sets (soft fingers, symmetric ones too)."""
    wrenches, inside = perturbed_grasp_wrenches(20, seed=7)
    mesh = trimesh.creation.box((0.05, 0.04, 0.07))
    from graspaug.grasping.contacts import close_fingers

    c = close_fingers(mesh, np.zeros((2, 3)), np.eye(3)[1:], 0.08)
    sym = grasp_wrenches(c.p1, c.n1, c.p2, c.n2, np.eye(3)[1:], mesh.center_mass, 0.5, 1000.0, 0.005)
    wrenches, inside = (
        np.concatenate([wrenches[inside][:10], sym.points]),
        np.concatenate([inside[inside][:10], sym.interior]),
    )
    eps = ferrari_canny(wrenches, inside)
    rng = np.random.default_rng(2)
    directions = rng.normal(size=(50_000, 6))
    directions /= np.linalg.norm(directions, axis=1, keepdims=True)
    for points, e in zip(wrenches, eps):
        assert e > 0
        assert (directions @ points.T).max(axis=1).min() >= e - 1e-12  # the ball of radius ε fits
        hull = ConvexHull(points)
        normal = hull.equations[np.argmin(-hull.equations[:, -1]), :6]
        assert boundary_distance_lp(points, normal) == pytest.approx(e, rel=1e-7)  # and touches the boundary


def test_qhull_epsilon_matches_support_function_and_lp():
    """On random wrench sets: every direction's support value is >= ε (the ball of radius ε
    fits), and an LP finds the boundary exactly at distance ε along the closest facet's normal."""
    rng = np.random.default_rng(1)
    directions = rng.normal(size=(200_000, 6))
    directions /= np.linalg.norm(directions, axis=1, keepdims=True)
    for _ in range(5):
        points = rng.normal(size=(20, 6)) * rng.uniform(0.5, 2.0, 6)
        eps = ferrari_canny_qhull(points)
        assert eps > 0
        support = (directions @ points.T).max(axis=1)
        assert support.min() >= eps - 1e-12
        hull = ConvexHull(points)
        normal = hull.equations[np.argmin(-hull.equations[:, -1]), :6]
        assert boundary_distance_lp(points, normal) == pytest.approx(eps, rel=1e-7)
    outside = rng.normal(size=(20, 6)) + 5.0  # origin outside the hull
    assert ferrari_canny_qhull(outside) == 0.0


def test_bad_wrench_shape_is_refused():
    with pytest.raises(ValueError, match="2m\\+4"):
        ferrari_canny(np.zeros((3, 19, 6)))
