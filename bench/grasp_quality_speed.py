"""Speed and exactness of our robust Ferrari-Canny against a plain qhull reference, in one run.

Both compute the robust ε (mean over perturbed samples) of the same grasps with the same
perturbations (same seeds), so the contacts and wrench sets are identical; they differ only
in how ε of each wrench set is found:

- plain reference: one ``scipy.spatial.ConvexHull`` per sample in a Python loop, ε = the
  smallest facet offset (``ferrari_canny_qhull``);
- ours: the compiled facet search of ``ferrari_canny`` over all samples at once.

Grasps: Dex-Net antipodal grasps (default params) on the first default shapes, as ingest
makes them, until ``--grasps`` are collected. Prints the time of each (whole robust metric
and ε alone), the speed ratio, and the largest difference of ε and of robust ε.

    python bench/grasp_quality_speed.py --grasps 2000
"""

from __future__ import annotations

import argparse
import time

import numpy as np
from _corpus import default_shapes

from graspaug.grasping.antipodal import sample_antipodal_grasps
from graspaug.grasping.quality import ferrari_canny, ferrari_canny_qhull
from graspaug.grasping.robust import robust_ferrari_canny
from graspaug.pipeline.params.model import GraspsParams
from graspaug.rng import shape_rng


class Timed:
    """An ε function that records its time and every value it returns."""

    def __init__(self, fn):
        self.fn, self.seconds, self.values = fn, 0.0, []

    def __call__(self, wrenches: np.ndarray, inside: np.ndarray) -> np.ndarray:
        start = time.perf_counter()
        out = self.fn(wrenches, inside)
        self.seconds += time.perf_counter() - start
        self.values.append(out)
        return out


def qhull_loop(wrenches: np.ndarray, inside: np.ndarray) -> np.ndarray:
    return np.array([ferrari_canny_qhull(w) for w in wrenches])


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--grasps", type=int, default=2000)
    parser.add_argument("--seed", type=int, default=0)
    args = parser.parse_args()

    cfg = GraspsParams()
    hand, quality, noise = cfg.gripper, cfg.quality, cfg.perturbations
    shapes = default_shapes(int(np.ceil(args.grasps / cfg.sampler.n_grasps)) + 5)
    jobs, total = [], 0
    for shape in shapes:
        if total >= args.grasps:
            break
        grasps = sample_antipodal_grasps(shape.mesh, hand, cfg.sampler, shape_rng(args.seed, shape.shape_id))
        grasps = grasps.take(np.arange(min(len(grasps), args.grasps - total)))
        jobs.append((shape, grasps))
        total += len(grasps)
    print(
        f"{total} grasps on {len(jobs)} default shapes, {noise.n_samples} perturbed samples each "
        f"({total * noise.n_samples} wrench sets)"
    )

    ferrari_canny(np.zeros((1, 2 * cfg.quality.cone_faces + 4, 6)))  # compile (cached on disk) before timing
    results = {}
    for name, fn in (("plain qhull loop", qhull_loop), ("ours", ferrari_canny)):
        timed = Timed(fn)
        start = time.perf_counter()
        robust = [
            robust_ferrari_canny(
                s.mesh, g.center, g.axis, hand, quality, noise, shape_rng(args.seed + 1, s.shape_id), epsilon=timed
            )[0]
            for s, g in jobs
        ]
        results[name] = (
            time.perf_counter() - start,
            timed.seconds,
            np.concatenate(robust),
            np.concatenate(timed.values),
        )
        print(
            f"{name:>16}: robust ε in {results[name][0]:7.2f} s, of which ε {timed.seconds:7.2f} s "
            f"({1e6 * timed.seconds / len(results[name][3]):.0f} µs per wrench set, {len(results[name][3])} not "
            "slipping)"
        )
    (t_ref, e_ref, robust_ref, eps_ref), (t_ours, e_ours, robust_ours, eps_ours) = results.values()
    print(f"speed ratio: {t_ref / t_ours:.1f}x on the whole robust metric, {e_ref / e_ours:.1f}x on ε alone")
    print(
        f"largest difference: ε {np.abs(eps_ref - eps_ours).max():.2e}, robust ε "
        f"{np.abs(robust_ref - robust_ours).max():.2e}"
    )
    print(
        f"robust ε > {cfg.threshold}: {np.mean(robust_ours > cfg.threshold):.1%} of grasps (same label for "
        f"{np.mean((robust_ours > cfg.threshold) == (robust_ref > cfg.threshold)):.2%})"
    )


if __name__ == "__main__":
    main()
