"""Grasp wrench spaces and the Ferrari-Canny quality ε, built exactly as Dex-Net builds them.

A two-contact grasp has a wrench matrix of ``2 m + 4`` points in R⁶ (``m`` friction-cone
faces, 8 by default), one row per wrench ``[force (N); s · torque (N·m)]``:

- rows ``0 .. m-1``: contact 1's cone generators ``f_j = n_in + μ (t1 cos 2πj/m + t2 sin 2πj/m)``
  in order around the cone, scaled by the normal force ``c = max(0, d · n_in)`` that the
  jaw moving along ``d`` can push with; torque ``(p - com) × f``, scaled by ``s``;
- rows ``m .. 2m-1``: contact 2, the same;
- rows ``2m .. 2m+3``: soft-finger torsion ``-τ1, -τ2, +τ1, +τ2`` with ``τ = π r² μ c n_in s``
  (zero force), in Dex-Net's column order.

ε is the distance from the origin to the boundary of the convex hull of these points (0 when
the origin is not strictly inside or the hull is flat): the smallest facet-plane offset.
:func:`ferrari_canny_qhull` computes it with one ``scipy.spatial.ConvexHull`` per grasp (about
1 ms each in 6-D); :func:`ferrari_canny` gets the same value (to 1e-9) 16-21x faster by trying
only the hyperplanes that can be facets of this particular point set (:func:`_epsilon_inside`).
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np
from numba import njit
from scipy.spatial import ConvexHull, QhullError

X_AXIS = np.array([1.0, 0.0, 0.0])
TANGENT_SEARCH_STEPS = 1000  # Dex-Net's Contact3D.tangents(max_samples=1000)
# Tolerances of the facet search, relative to the largest wrench coordinate (at least 1):
RANK_TOL = 1e-12  # a point adds no rank if its reduced row is smaller than this
SIDE_TOL = 1e-11  # a point this close to a plane lies on it
PIN_TOL = 1e-12  # torsion points that pin a plane family's member this weakly pin none
INTERIOR_MARGIN = 1e-9  # the contact line must be this far (relatively) inside both cones


def _theta_table(steps: int) -> np.ndarray:
    """The angles Dex-Net's tangent search visits, accumulated in the same order (bit-identical)."""
    out = np.empty(steps)
    theta, d_theta = 0.0, 2 * np.pi / float(steps)
    for i in range(steps):
        out[i] = theta
        theta = theta + d_theta
    return out


_THETAS = _theta_table(TANGENT_SEARCH_STEPS)


def contact_frames(in_normal: np.ndarray, x_axis: np.ndarray = X_AXIS) -> tuple[np.ndarray, np.ndarray]:
    """Tangents ``t1, t2`` (N, 3) at contacts with unit inward normals ``in_normal`` (N, 3).

    Dex-Net's ``Contact3D.tangents``: an SVD basis of the tangent plane made right-handed
    with the normal, then ``t1`` turned (in 2π/1000 steps) to the direction of largest dot
    product with ``x_axis`` (the object's x axis), and ``t2 = n_in × t1``.
    """
    d = np.asarray(in_normal, dtype=float)
    u = np.linalg.svd(d[:, :, None])[0]  # (N, 3, 3); columns 1 and 2 span the tangent plane
    x, y = u[:, :, 1].copy(), u[:, :, 2].copy()
    y[np.einsum("ij,ij->i", np.cross(x, y), d) < 0] *= -1
    ax, ay = x @ x_axis, y @ x_axis
    # The search's winner is the step nearest atan2(ay, ax); evaluate its neighbours exactly.
    steps = TANGENT_SEARCH_STEPS
    nearest = np.rint(np.mod(np.arctan2(ay, ax), 2 * np.pi) / (2 * np.pi / steps)).astype(np.int64)
    candidates = np.sort(np.mod(nearest[:, None] + np.arange(-2, 3), steps), axis=1)
    theta = _THETAS[candidates]
    score = np.cos(theta) * ax[:, None] + np.sin(theta) * ay[:, None]
    best = np.argmax(score, axis=1)
    rows = np.arange(len(d))
    best_theta = np.where(score[rows, best] > 0, theta[rows, best], 0.0)
    t1 = np.cos(best_theta)[:, None] * x + np.sin(best_theta)[:, None] * y
    return t1, np.cross(d, t1)


class GraspWrenches(NamedTuple):
    """Wrench sets of N grasps and what their geometry already tells about them."""

    points: np.ndarray  # (N, 2m+4, 6) wrench points, layout in the module docstring
    slips: np.ndarray  # (N,) bool: a jaw's push lies outside its friction cone (Dex-Net: quality 0)
    interior: np.ndarray  # (N,) bool: the origin is strictly inside the hull (force closure), see grasp_wrenches


def grasp_wrenches(
    p1: np.ndarray,
    n1: np.ndarray,
    p2: np.ndarray,
    n2: np.ndarray,
    axis: np.ndarray,
    com: np.ndarray,
    friction_coef: float | np.ndarray,
    torque_scaling: float,
    finger_radius: float,
    cone_faces: int = 8,
    x_axis: np.ndarray = X_AXIS,
) -> GraspWrenches:
    """Wrench points (N, 2m+4, 6) of grasps, whether a contact slips, and whether the origin is
    known to be inside their hull.

    ``p1, p2`` (N, 3) contacts (m); ``n1, n2`` (N, 3) unit outward surface normals there;
    ``axis`` (N, 3) unit grasp axis: jaw 1 pushes along ``+axis``, jaw 2 along ``-axis``;
    ``com`` (3,) center of mass (m); ``friction_coef`` scalar or (N,); ``torque_scaling`` s
    (1/m); ``finger_radius`` (m) of the soft contact, 0 for hard fingers.
    A contact slips (Dex-Net: the grasp has quality 0) when the jaw's push lies outside its
    friction cone: ``μ d·n_in < |tangential part of d|``.

    ``interior`` marks grasps whose contact line ``ℓ = p2 - p1`` lies strictly inside contact 1's
    polyhedral cone and ``-ℓ`` inside contact 2's, with both pushes, μ, r and s nonzero. Then
    the origin is strictly inside the hull. Proof: let ``u = (a, b)`` have ``u · w <= 0`` for
    every point. Torsion comes in ± pairs, so ``b ⟂ n_in,1``. Each generator gives
    ``f · g_i <= 0`` with ``g_i = a + s b × (p_i - com)``, i.e. ``g_i`` is in the polar of cone
    i; ``ℓ`` inside cone 1 gives ``g_1 · ℓ <= 0`` (= 0 only if ``g_1 = 0``), ``-ℓ`` inside cone 2
    gives ``g_2 · ℓ >= 0``; but ``g_1 - g_2 = s b × ℓ`` is ``⟂ ℓ``, so both vanish, ``b × ℓ = 0``,
    ``b ∥ ℓ``, and ``b ⟂ n_in,1`` with ``ℓ · n_in,1 > 0`` leaves ``b = 0``, then ``a = 0``.
    """
    axis = np.asarray(axis, dtype=float)
    n = len(axis)
    mu = np.broadcast_to(np.asarray(friction_coef, dtype=float), (n,))
    phi = np.array([2 * np.pi * (float(j) / cone_faces) for j in range(cone_faces)])
    rows = np.empty((n, 2 * cone_faces + 4, 6))
    slips = np.zeros(n, dtype=bool)
    line = np.asarray(p2, dtype=float) - np.asarray(p1, dtype=float)
    interior = (mu > 0) & (finger_radius > 0) & (torque_scaling != 0) & (np.linalg.norm(line, axis=1) > 0)
    edge_normals = phi + np.pi / cone_faces  # the cone polygon's edges, at distance μ cos(π/m)
    for k, (p, normal, push) in enumerate(((p1, n1, axis), (p2, n2, -axis))):
        in_normal = -np.asarray(normal, dtype=float)
        t1, t2 = contact_frames(in_normal, x_axis)
        normal_push = np.einsum("ij,ij->i", push, in_normal)
        tangential_push = np.hypot(np.einsum("ij,ij->i", push, t1), np.einsum("ij,ij->i", push, t2))
        slips |= mu * normal_push < tangential_push
        c = np.maximum(normal_push, 0.0)
        toward = line if k == 0 else -line
        height = np.einsum("ij,ij->i", toward, in_normal)
        with np.errstate(divide="ignore", invalid="ignore"):
            x, y = np.einsum("ij,ij->i", toward, t1) / height, np.einsum("ij,ij->i", toward, t2) / height
            reach = x[:, None] * np.cos(edge_normals) + y[:, None] * np.sin(edge_normals)
            interior &= (
                (c > 0)
                & (height > 0)
                & np.all(reach < (1 - INTERIOR_MARGIN) * mu[:, None] * np.cos(np.pi / cone_faces), axis=1)
            )
        tangent = t1[:, None, :] * np.cos(phi)[None, :, None] + t2[:, None, :] * np.sin(phi)[None, :, None]
        cone = in_normal[:, None, :] + mu[:, None, None] * tangent  # (N, m, 3)
        torques = np.cross((np.asarray(p, dtype=float) - com)[:, None, :], cone)
        block = slice(k * cone_faces, (k + 1) * cone_faces)
        rows[:, block, :3] = c[:, None, None] * cone
        rows[:, block, 3:] = torque_scaling * (c[:, None, None] * torques)
        torsion = np.pi * finger_radius**2 * mu[:, None] * (c[:, None] * in_normal) * torque_scaling
        for row, sign in ((2 * cone_faces + k, -1.0), (2 * cone_faces + 2 + k, 1.0)):  # -τ1, -τ2, +τ1, +τ2
            rows[:, row, :3] = 0.0
            rows[:, row, 3:] = sign * torsion
    return GraspWrenches(rows, slips, interior)


def ferrari_canny_qhull(wrenches: np.ndarray) -> float:
    """ε of one wrench set (P, 6) from the facet offsets of ``scipy.spatial.ConvexHull`` (qhull).

    The plain reference: qhull's ``equations`` are unit normals ``a`` and offsets ``b`` with
    ``a·x + b <= 0`` inside, so the origin is at distance ``-b`` from each facet plane.
    """
    try:
        hull = ConvexHull(wrenches)
    except QhullError:  # flat or degenerate: no 6-D hull, no force closure
        return 0.0
    distances = -hull.equations[:, -1]
    return float(distances.min()) if distances.min() > 0 else 0.0


def _polygon_faces(cone_faces: int) -> tuple[np.ndarray, np.ndarray]:
    """Faces of a cone polygon as (2m + 2, 3) point indices (padded with -1) and their sizes:
    nothing, each vertex, each edge of adjacent generators, the whole polygon (3 of its points)."""
    m = cone_faces
    faces = [()] + [(i,) for i in range(m)] + [(i, (i + 1) % m) for i in range(m)] + [(0, m // 3, (2 * m) // 3)]
    rows = np.full((len(faces), 3), -1, dtype=np.int64)
    for i, face in enumerate(faces):
        rows[i, : len(face)] = face
    return rows, np.array([len(f) for f in faces], dtype=np.int64)


_TORSION_PAIRS = np.array([[0, 1], [0, 3], [2, 1], [2, 3]])  # (±τ1, ±τ2) among rows -τ1, -τ2, +τ1, +τ2


@njit(cache=True)
def _add_row(a: np.ndarray, pivots: np.ndarray, rank: int, point: np.ndarray, tol: float) -> int:
    """Append ``[point, -1]`` to the row-echelon rows ``a[:rank]`` (pivot columns ``pivots``);
    the new rank (unchanged if the point lies on the affine span of the others)."""
    for j in range(6):
        a[rank, j] = point[j]
    a[rank, 6] = -1.0  # [w, -1] · [u, d] = 0  <=>  u · w = d
    for i in range(rank):
        f = a[rank, pivots[i]] / a[i, pivots[i]]
        if f != 0.0:
            for j in range(7):
                a[rank, j] -= f * a[i, j]
        a[rank, pivots[i]] = 0.0
    big, col = tol, -1
    for j in range(7):
        if abs(a[rank, j]) > big:
            used = False
            for i in range(rank):
                used |= pivots[i] == j
            if not used:
                big, col = abs(a[rank, j]), j
    if col < 0:
        return rank
    pivots[rank] = col
    return rank + 1


@njit(cache=True)
def _null_basis(a: np.ndarray, pivots: np.ndarray, rank: int, basis: np.ndarray) -> int:
    """Rows ``basis[:7 - rank]`` := a basis of the hyperplanes ``[u, d]`` through the points
    of the row-echelon rows ``a[:rank]``; returns their number."""
    q = 0
    for free in range(7):
        used = False
        for i in range(rank):
            used |= pivots[i] == free
        if used:
            continue
        x = basis[q]
        for j in range(7):
            x[j] = 0.0
        x[free] = 1.0
        for i in range(rank - 1, -1, -1):
            s = 0.0
            for j in range(7):
                s += a[i, j] * x[j]
            x[pivots[i]] = -s / a[i, pivots[i]]
        q += 1
    return q


@njit(cache=True)
def _supporting_offset(x: np.ndarray, points: np.ndarray, n_points: int, side_tol: float) -> float:
    """For the hyperplane ``x[:6] · w = x[6]``: its distance from the origin (m), negative if the
    origin is beyond it, when ``points[:n_points]`` all lie on one side; +inf if they do not,
    -inf if they all lie on it (a flat set)."""
    norm = np.sqrt(x[0] ** 2 + x[1] ** 2 + x[2] ** 2 + x[3] ** 2 + x[4] ** 2 + x[5] ** 2)
    if norm == 0.0:
        return np.inf
    above = below = False
    for i in range(n_points):
        v = -x[6]
        for j in range(6):
            v += x[j] * points[i, j]
        v /= norm
        if v > side_tol:
            above = True
            if below:
                return np.inf
        elif v < -side_tol:
            below = True
            if above:
                return np.inf
    if not above and not below:
        return -np.inf
    return x[6] / norm if below else -x[6] / norm


@njit(cache=True)
def _origin_not_inside(
    points: np.ndarray, poly: np.ndarray, poly_n: np.ndarray, rank_tol: float, side_tol: float
) -> bool:
    """Whether some hyperplane through the origin has every wrench point (2m+4, 6) on one side.

    Such a plane contains ``±τ1, ±τ2``, so it passes through the origin, ``τ1``, ``τ2`` and
    faces of the two cone polygons: those are the planes tried."""
    m = (points.shape[0] - 4) // 2
    a = np.empty((9, 7))
    pivots = np.empty(9, dtype=np.int64)
    basis = np.empty((7, 7))
    origin = np.zeros(6)
    rank_t = _add_row(a, pivots, 0, origin, rank_tol)
    rank_t = _add_row(a, pivots, rank_t, points[2 * m + 2], rank_tol)  # +τ1
    rank_t = _add_row(a, pivots, rank_t, points[2 * m + 3], rank_tol)  # +τ2
    for ai in range(poly.shape[0]):
        rank_a = rank_t
        for r in range(poly_n[ai]):
            rank_a = _add_row(a, pivots, rank_a, points[poly[ai, r]], rank_tol)
        if rank_a > 6:
            continue
        for bi in range(poly.shape[0]):
            rank = rank_a
            for r in range(poly_n[bi]):
                rank = _add_row(a, pivots, rank, points[m + poly[bi, r]], rank_tol)
            if rank != 6:
                continue
            _null_basis(a, pivots, rank, basis)
            if _supporting_offset(basis[0], points, points.shape[0], side_tol) < np.inf:
                return True
    return False


@njit(cache=True)
def _epsilon_inside(
    points: np.ndarray, poly: np.ndarray, poly_n: np.ndarray, rank_tol: float, side_tol: float
) -> float:
    """ε of one wrench set (2m+4, 6) whose hull has the origin strictly inside.

    A facet's plane then meets each cone polygon in a face of it (:func:`_polygon_faces`) and
    the torsion points in nothing, one point or a pair ``(±τ1, ±τ2)`` (any other pair or triple
    spans a line or plane through the origin). For every pair of polygon faces, the planes
    through them form a ``q``-dimensional family (q = 7 - rank); with q = 1, 2, 3 the facet
    candidates are that plane, or the family's member through each torsion point, or through
    each torsion pair. ε is the smallest offset among candidates with every point on one side.
    """
    m = (points.shape[0] - 4) // 2
    n_points = points.shape[0]
    a = np.empty((9, 7))
    pivots = np.empty(9, dtype=np.int64)
    basis = np.empty((7, 7))
    g = np.empty((4, 3))  # torsion point t against basis plane j: [τ_t, -1] · basis_j
    x = np.empty(7)
    best = np.inf
    for ai in range(poly.shape[0]):
        rank_a = 0
        for r in range(poly_n[ai]):
            rank_a = _add_row(a, pivots, rank_a, points[poly[ai, r]], rank_tol)
        for bi in range(poly.shape[0]):
            if poly_n[ai] + poly_n[bi] < 4:
                continue
            rank = rank_a
            for r in range(poly_n[bi]):
                rank = _add_row(a, pivots, rank, points[m + poly[bi, r]], rank_tol)
            q = 7 - rank
            if q < 1 or q > 3:
                continue
            _null_basis(a, pivots, rank, basis)
            for t in range(4):
                for j in range(q):
                    v = -basis[j, 6]
                    for k in range(3, 6):
                        v += basis[j, k] * points[2 * m + t, k]
                    g[t, j] = v
            for option in range(1 if q == 1 else 4):
                if q == 1:
                    c0, c1, c2 = 1.0, 0.0, 0.0
                elif q == 2:  # the member through torsion point `option`
                    c0, c1, c2 = g[option, 1], -g[option, 0], 0.0
                    if abs(c0) + abs(c1) <= PIN_TOL * (np.abs(basis[0]).max() + np.abs(basis[1]).max()):
                        continue
                else:  # the member through torsion pair `option`
                    u, w = _TORSION_PAIRS[option, 0], _TORSION_PAIRS[option, 1]
                    c0 = g[u, 1] * g[w, 2] - g[u, 2] * g[w, 1]
                    c1 = g[u, 2] * g[w, 0] - g[u, 0] * g[w, 2]
                    c2 = g[u, 0] * g[w, 1] - g[u, 1] * g[w, 0]
                    size = np.sqrt(
                        (g[u, 0] ** 2 + g[u, 1] ** 2 + g[u, 2] ** 2) * (g[w, 0] ** 2 + g[w, 1] ** 2 + g[w, 2] ** 2)
                    )
                    if np.sqrt(c0 * c0 + c1 * c1 + c2 * c2) <= PIN_TOL * size:
                        continue  # the two points pin down no single plane
                for j in range(7):
                    x[j] = c0 * basis[0, j]
                    if q > 1:
                        x[j] += c1 * basis[1, j]
                    if q > 2:
                        x[j] += c2 * basis[2, j]
                offset = _supporting_offset(x, points, n_points, side_tol)
                if offset == np.inf:
                    continue
                if offset <= 0.0:
                    return 0.0  # on the boundary after all (to rounding)
                best = min(best, offset)
    return best if best < np.inf else 0.0


@njit(cache=True)
def _epsilon_batch(
    wrenches: np.ndarray, inside: np.ndarray, poly: np.ndarray, poly_n: np.ndarray, out: np.ndarray
) -> None:
    for i in range(wrenches.shape[0]):
        points = wrenches[i]
        scale = max(1.0, np.abs(points).max())
        rank_tol, side_tol = RANK_TOL * scale, SIDE_TOL * scale
        if not inside[i] and _origin_not_inside(points, poly, poly_n, rank_tol, side_tol):
            out[i] = 0.0
        else:
            out[i] = _epsilon_inside(points, poly, poly_n, rank_tol, side_tol)


_FACES: dict[int, tuple[np.ndarray, np.ndarray]] = {}


def ferrari_canny(wrenches: np.ndarray, inside: np.ndarray | None = None) -> np.ndarray:
    """ε (N,) of wrench sets (N, 2m+4, 6) laid out as :func:`grasp_wrenches` makes them.

    ``inside`` (N,) bool may mark sets known to hold the origin strictly inside their hull
    (``GraspWrenches.interior``); the others are checked first. Equal to
    :func:`ferrari_canny_qhull` to rounding, and compiled (numba): 50-70 µs per grasp instead
    of ~1 ms (bench/grasp_quality_speed.py).
    """
    wrenches = np.ascontiguousarray(wrenches, dtype=float)
    cone_faces = (wrenches.shape[1] - 4) // 2 if wrenches.ndim == 3 else 0
    if wrenches.ndim != 3 or wrenches.shape[2] != 6 or 2 * cone_faces + 4 != wrenches.shape[1] or cone_faces < 3:
        raise ValueError(f"wrenches must be (N, 2m+4, 6) with m >= 3 cone faces, got {wrenches.shape}")
    inside = np.zeros(len(wrenches), dtype=bool) if inside is None else np.ascontiguousarray(inside, dtype=bool)
    if inside.shape != (len(wrenches),):
        raise ValueError(f"inside must be ({len(wrenches)},) bool, got shape {inside.shape}")
    if cone_faces not in _FACES:
        _FACES[cone_faces] = _polygon_faces(cone_faces)
    out = np.zeros(len(wrenches))
    _epsilon_batch(wrenches, inside, *_FACES[cone_faces], out)
    return out
