"""Grasp wrench spaces and the Ferrari-Canny quality ε, built exactly as Dex-Net builds them.

A two-contact grasp has a wrench matrix of ``2 m + 4`` points in R⁶ (``m`` friction-cone
faces, 8 by default), one row per wrench ``[force (N); s · torque (N·m)]``:

- rows ``0 .. m-1``: contact 1's cone generators ``f_j = n_in + μ (t1 cos 2πj/m + t2 sin 2πj/m)``
  in order around the cone, scaled by the normal force ``c = max(0, d · n_in)`` that the
  jaw moving along ``d`` can push with; torque ``(p - com) × f``, scaled by ``s``;
- rows ``m .. 2m-1``: contact 2, the same;
- rows ``2m .. 2m+3``: soft-finger torsion ``+τ1, -τ1, +τ2, -τ2`` with ``τ = π r² μ c n_in s``
  (zero force).

ε is the distance from the origin to the boundary of the convex hull of these points (0 when
the origin is not strictly inside or the hull is flat): the smallest facet-plane offset.
:func:`ferrari_canny_qhull` computes it with one ``scipy.spatial.ConvexHull`` per grasp (about
1 ms each in 6-D); :func:`ferrari_canny` gets the same value ~30x faster by visiting only
the hyperplanes that can be facets of this particular point set (see :func:`_candidate_rows`).
"""
from __future__ import annotations

import numpy as np
from numba import njit
from scipy.spatial import ConvexHull, QhullError

X_AXIS = np.array([1.0, 0.0, 0.0])
TANGENT_SEARCH_STEPS = 1000  # Dex-Net's Contact3D.tangents(max_samples=1000)


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
) -> tuple[np.ndarray, np.ndarray]:
    """Wrench points (N, 2m+4, 6) of grasps and whether a contact slips (N,) bool.

    ``p1, p2`` (N, 3) contacts (m); ``n1, n2`` (N, 3) unit outward surface normals there;
    ``axis`` (N, 3) unit grasp axis: jaw 1 pushes along ``+axis``, jaw 2 along ``-axis``;
    ``com`` (3,) center of mass (m); ``friction_coef`` scalar or (N,); ``torque_scaling`` s
    (1/m); ``finger_radius`` (m) of the soft contact, 0 for hard fingers.
    A contact slips (Dex-Net: the grasp has quality 0) when the jaw's push lies outside its
    friction cone: ``μ d·n_in < |tangential part of d|``.
    """
    axis = np.asarray(axis, dtype=float)
    n = len(axis)
    mu = np.broadcast_to(np.asarray(friction_coef, dtype=float), (n,))
    phi = np.array([2 * np.pi * (float(j) / cone_faces) for j in range(cone_faces)])
    rows = np.empty((n, 2 * cone_faces + 4, 6))
    slips = np.zeros(n, dtype=bool)
    for k, (p, normal, push) in enumerate(((p1, n1, axis), (p2, n2, -axis))):
        in_normal = -np.asarray(normal, dtype=float)
        t1, t2 = contact_frames(in_normal, x_axis)
        normal_push = np.einsum("ij,ij->i", push, in_normal)
        tangential_push = np.hypot(np.einsum("ij,ij->i", push, t1), np.einsum("ij,ij->i", push, t2))
        slips |= mu * normal_push < tangential_push
        c = np.maximum(normal_push, 0.0)
        tangent = t1[:, None, :] * np.cos(phi)[None, :, None] + t2[:, None, :] * np.sin(phi)[None, :, None]
        cone = in_normal[:, None, :] + mu[:, None, None] * tangent  # (N, m, 3)
        torques = np.cross((np.asarray(p, dtype=float) - com)[:, None, :], cone)
        block = slice(k * cone_faces, (k + 1) * cone_faces)
        rows[:, block, :3] = c[:, None, None] * cone
        rows[:, block, 3:] = torque_scaling * (c[:, None, None] * torques)
        torsion = np.pi * finger_radius**2 * mu[:, None] * (c[:, None] * in_normal) * torque_scaling
        rows[:, 2 * cone_faces + 2 * k, :3] = 0.0
        rows[:, 2 * cone_faces + 2 * k, 3:] = torsion
        rows[:, 2 * cone_faces + 2 * k + 1, :3] = 0.0
        rows[:, 2 * cone_faces + 2 * k + 1, 3:] = -torsion
    return rows, slips


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


def _face_table(cone_faces: int) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """The point subsets whose affine hulls can be facets' (see :func:`_epsilon`).

    Returns torsion-side options ``(10, 3)`` and polygon faces ``(2m + 2, 3)`` as row indices
    (padded with -1) with their sizes. Row ``2m + 4`` is the origin (appended by the caller).

    A facet's hyperplane meets each contact's cone polygon (a regular m-gon in a 2-D plane
    of R⁶) in one face of it: nothing, a vertex, an edge of adjacent generators, or the whole
    polygon (any 3 of its points span it). Since the torsion points come in pairs ``±τ``,
    the origin is always in the hull; either it is strictly inside, and then a facet meets
    ``{±τ1, ±τ2}`` in nothing, one point or one of the 4 pairs ``(±τ1, ±τ2)`` (any other pair
    or triple spans a line or plane through the origin); or a supporting hyperplane passes
    through the origin and then contains ``±τ1, ±τ2``, so its affine hull is spanned by the
    origin, ``τ1``, ``τ2`` and faces of the polygons.
    """
    m = cone_faces
    t, origin = 2 * m, 2 * m + 4  # rows t..t+3: +τ1, -τ1, +τ2, -τ2
    torsion = [(origin, t, t + 2), (), (t,), (t + 1,), (t + 2,), (t + 3,), (t, t + 2), (t, t + 3), (t + 1, t + 2), (t + 1, t + 3)]
    polygon = [()] + [(i,) for i in range(m)] + [(i, (i + 1) % m) for i in range(m)] + [(0, m // 3, (2 * m) // 3)]

    def table(faces: list[tuple[int, ...]]) -> tuple[np.ndarray, np.ndarray]:
        rows = np.full((len(faces), 3), -1, dtype=np.int64)
        for i, face in enumerate(faces):
            rows[i, : len(face)] = face
        return rows, np.array([len(f) for f in faces], dtype=np.int64)

    return (*table(torsion), *table(polygon))


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
def _plane_offset(a: np.ndarray, pivots: np.ndarray, points: np.ndarray, side_tol: float, x: np.ndarray) -> float:
    """For the hyperplane through rows ``a[:6]`` (rank 6): its offset from the origin (m)
    if every point lies on one side of it, +inf if not, -inf if every point lies on it."""
    free = 21  # the column without a pivot
    for j in range(7):
        used = False
        for i in range(6):
            used |= pivots[i] == j
        if not used:
            free = j
    for j in range(7):
        x[j] = 0.0
    x[free] = 1.0
    for i in range(5, -1, -1):
        s = 0.0
        for j in range(7):
            s += a[i, j] * x[j]
        x[pivots[i]] = -s / a[i, pivots[i]]
    norm = np.sqrt(x[0] ** 2 + x[1] ** 2 + x[2] ** 2 + x[3] ** 2 + x[4] ** 2 + x[5] ** 2)
    if norm == 0.0:
        return np.inf
    above = below = False
    for i in range(points.shape[0]):
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
def _epsilon(points: np.ndarray, tors: np.ndarray, tors_n: np.ndarray, poly: np.ndarray, poly_n: np.ndarray, rank_tol: float, side_tol: float) -> float:
    """ε of one wrench set (2m+5, 6) whose last row is the origin: the smallest offset among
    the hyperplanes through the point subsets of :func:`_face_table` that have every point on
    one side (tolerance ``side_tol``); 0 if such a plane passes through the origin or all
    points lie on one plane."""
    m = (points.shape[0] - 5) // 2
    a = np.empty((9, 7))
    pivots = np.empty(9, dtype=np.int64)
    x = np.empty(7)
    best = np.inf
    for ti in range(tors.shape[0]):
        rank_t = 0
        for r in range(tors_n[ti]):
            rank_t = _add_row(a, pivots, rank_t, points[tors[ti, r]], rank_tol)
        for ai in range(poly.shape[0]):
            if tors_n[ti] + poly_n[ai] + 3 < 6:
                continue
            rank_a = rank_t
            for r in range(poly_n[ai]):
                rank_a = _add_row(a, pivots, rank_a, points[poly[ai, r]], rank_tol)
            if rank_a > 6:
                continue
            for bi in range(poly.shape[0]):
                if tors_n[ti] + poly_n[ai] + poly_n[bi] < 6:
                    continue
                rank = rank_a
                for r in range(poly_n[bi]):
                    rank = _add_row(a, pivots, rank, points[poly[bi, r] + m], rank_tol)
                if rank != 6:
                    continue
                offset = _plane_offset(a, pivots, points, side_tol, x)
                if offset <= 0.0:
                    return 0.0  # flat hull, or the origin on or beyond this facet
                best = min(best, offset)
    return best if best < np.inf else 0.0


@njit(cache=True)
def _epsilon_batch(wrenches: np.ndarray, tors: np.ndarray, tors_n: np.ndarray, poly: np.ndarray, poly_n: np.ndarray, out: np.ndarray) -> None:
    points = np.zeros((wrenches.shape[1] + 1, 6))  # the last row stays the origin
    for i in range(wrenches.shape[0]):
        points[:-1] = wrenches[i]
        scale = max(1.0, np.abs(wrenches[i]).max())
        out[i] = _epsilon(points, tors, tors_n, poly, poly_n, 1e-12 * scale, 1e-11 * scale)


_FACES: dict[int, tuple[np.ndarray, ...]] = {}


def ferrari_canny(wrenches: np.ndarray) -> np.ndarray:
    """ε (N,) of wrench sets (N, 2m+4, 6) laid out as :func:`grasp_wrenches` makes them.

    Equal to :func:`ferrari_canny_qhull` (to rounding) and compiled (numba), so it runs
    in tens of microseconds per grasp instead of a millisecond.
    """
    wrenches = np.ascontiguousarray(wrenches, dtype=float)
    cone_faces = (wrenches.shape[1] - 4) // 2
    if wrenches.ndim != 3 or wrenches.shape[2] != 6 or 2 * cone_faces + 4 != wrenches.shape[1] or cone_faces < 3:
        raise ValueError(f"wrenches must be (N, 2m+4, 6) with m >= 3 cone faces, got {wrenches.shape}")
    if cone_faces not in _FACES:
        _FACES[cone_faces] = _face_table(cone_faces)
    out = np.zeros(len(wrenches))
    _epsilon_batch(wrenches, *_FACES[cone_faces], out)
    return out
