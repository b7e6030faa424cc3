"""Speed and exactness of the objects' bootstrap of AP (what ``graspaug evaluate`` spends on each network), the binned
path against the object loop it replaced, in one run.

Both compute every resample's AP of the same networks' scores under the same resamples of the objects
(:class:`graspaug.experiments.stats.ObjectBootstrap`); they differ only in how the objects' counts up to each threshold
that holds a positive are found:

- reference: :meth:`~graspaug.experiments.stats.ObjectBootstrap.average_precision_by_objects`, one object at a time
  (searches of its datapoints), three products of the counts;
- ours: :meth:`~graspaug.experiments.stats.ObjectBootstrap.average_precision`, every datapoint binned at once by
  (object, threshold), two products.

Synthetic data shaped like ``evaluate`` of the confirmatory networks on the 68 YCB objects: ``--networks`` networks
scoring ``--datapoints`` datapoints of ``--objects`` objects of uneven sizes, 30% positive, float32 scores (each
network its own noise), ``--resamples`` resamples. Prints each path's seconds (whole run, each path once over all
networks, the two taking turns over ``--rounds`` rounds), the time ratio reference / ours (above 1: ours is faster),
the largest difference of any resample's AP, and the load average (the machine may be shared).

    python bench/bootstrap_speed.py [--networks 48] [--datapoints 23524] [--objects 68] [--resamples 1000]
"""

from __future__ import annotations

import argparse
import os
import statistics
import time

import numpy as np

from graspaug.experiments.stats import ObjectBootstrap


def synthetic(networks: int, datapoints: int, objects: int, seed: int = 0):
    """Objects of uneven sizes (Dirichlet shares), 30% positive labels, ``networks`` float32 score vectors."""
    rng = np.random.default_rng(seed)
    ids = rng.choice(objects, size=datapoints, p=rng.dirichlet(np.full(objects, 2.0)))
    labels = rng.random(datapoints) < 0.3
    scores = [(labels * rng.uniform(0.5, 2) + rng.normal(0, 1, datapoints)).astype(np.float32) for _ in range(networks)]
    return ids, labels, scores


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--networks", type=int, default=48)
    parser.add_argument("--datapoints", type=int, default=23524)
    parser.add_argument("--objects", type=int, default=68)
    parser.add_argument("--resamples", type=int, default=1000)
    parser.add_argument("--rounds", type=int, default=3)
    args = parser.parse_args()
    ids, labels, scores = synthetic(args.networks, args.datapoints, args.objects)
    boot = ObjectBootstrap(ids, args.resamples, 0)
    boot.average_precision(labels, scores[0]), boot.average_precision_by_objects(labels, scores[0])  # warm up
    load_before = os.getloadavg()[0]
    times = {"reference": [], "ours": []}
    worst = 0.0
    for _ in range(args.rounds):
        start = time.perf_counter()
        old = [boot.average_precision_by_objects(labels, s) for s in scores]
        times["reference"].append(time.perf_counter() - start)
        start = time.perf_counter()
        new = [boot.average_precision(labels, s) for s in scores]
        times["ours"].append(time.perf_counter() - start)
        worst = max(worst, max(float(np.nanmax(np.abs(a - b))) for a, b in zip(old, new, strict=True)))
    ref, ours = statistics.median(times["reference"]), statistics.median(times["ours"])
    print(
        f"{args.networks} networks x {args.datapoints} datapoints x {args.objects} objects, {args.resamples} "
        f"resamples; {os.cpu_count()} cores, load average {load_before:.2f} before, {os.getloadavg()[0]:.2f} after"
    )
    print(f"reference (object loop): {ref:.2f} s  ({', '.join(f'{t:.2f}' for t in times['reference'])})")
    print(f"ours (binned):           {ours:.2f} s  ({', '.join(f'{t:.2f}' for t in times['ours'])})")
    print(f"ratio reference / ours: {ref / ours:.2f}x; largest difference of a resample's AP: {worst:.1e}")


if __name__ == "__main__":
    main()
