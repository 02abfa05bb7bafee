#!/usr/bin/env python3
"""Modelled speed-up of the distributed bake on M machines (issue #16), from measured inputs.

Inputs: the --stats JSON of a 1 rank × 2 threads bake and of the same bake as 2 ranks × 1
thread (bench/mpi_scaling.sh writes NAME.1x2.json and NAME.2x1.json). From them:

  rays/core-s   visibility rays per second per core (Σ rank rays / Σ rank visibility seconds)
  V, F, G       core-seconds of the divisible work: visibility, first shot, gather (Σ over
                ranks of rank_visibility_seconds and rank_gather_seconds; F = ranks × the
                smallest rank_first_shot_seconds, which include the wait at the first exchange)
  R             per iteration, the work every rank repeats for all tixels (transport refresh,
                change, power sums; rank 0's propagation − first shot − gather − exchange, / iterations)
  X             the rest: 1x2 seconds − visibility − propagation: loading, parameterisation and
                BVH, which every rank repeats (X0, given with --fixed S, measured by the time
                `plenoptic bake` takes to print its "parameterisation:" line; default: all of X),
                and writing the .plv, which each rank does for its own shard (X − X0, divided by M)
  B, I, bytes   batches (one allgatherv each per iteration), iterations, values × 12 bytes

Model, M machines like this one (C = 2 cores each), one rank per machine:

  T(M) = X0 + (X − X0)/M + k·(V + F + G)/(C·M) + (I + 1)·(B·α·⌈log2 M⌉ + β·values·12·(M−1)/M) + I·R

  k      load imbalance of the divisible work, measured at 2 ranks (max/mean of the ranks'
         visibility + gather seconds), assumed to hold at M
  α      latency of one allgatherv stage, 50 µs (10 GbE, recursive doubling: ⌈log2 M⌉ stages)
  β      1 / (1 GB/s) per byte received (10 GbE; an allgather receives (M−1)/M of the values)
  R      conservatively not divided by the threads (it was measured with 1 thread)

Speed-up S(M) = T(1) / T(M). `--scale NAME TIXELS DIRS VALUES ITER X0` models another preset of the
same scene from the measured one: visibility, gather and the .plv write ∝ tixels × directions,
first shot ∝ tixels, R and the exchange ∝ values, batches ∝ tixels (≤ 16000), X0 as given (the
time to that preset's "parameterisation:" line).

Usage: bench/mpi_model.py ONE_X_TWO.json TWO_X_ONE.json [--dirs N] [--fixed S] [--scale NAME TIXELS DIRS VALUES ITERATIONS X0]...
  --dirs N   gather directions of the measured runs (default 256, the default preset)
  --fixed S  X0, the seconds of X every rank repeats (default: all of X)
"""
import json
import math
import sys

ALPHA = 50e-6  # s per allgatherv stage
BETA = 1.0 / 1.0e9  # s per byte
CORES = 2
MACHINES = [1, 4, 16, 64]


def load(path):
    with open(path) as f:
        return json.load(f)


def inputs(one, two):
    ranks = two["ranks"]
    vis = sum(two["rank_visibility_seconds"])
    # A rank's first-shot seconds include its wait at the first exchange (for the slowest rank's
    # visibility): the rank that arrived last waited least, so its time stands for every rank's.
    fs = ranks * min(two["rank_first_shot_seconds"])
    gather = sum(two["rank_gather_seconds"])
    rays = sum(two["rank_visibility_rays"])
    per_rank = [two["rank_visibility_seconds"][r] + two["rank_gather_seconds"][r] for r in range(ranks)]
    imbalance = max(per_rank) / (sum(per_rank) / ranks)
    iterations = two["iterations"]
    repeated = (two["rank_propagation_seconds"][0] - two["rank_first_shot_seconds"][0] - two["rank_gather_seconds"][0] -
                two["exchange_seconds"]) / iterations
    fixed = one["seconds"] - one["visibility_seconds"] - one["propagation_seconds"]
    return dict(tixels=two["tixels"], dirs=None, values=two["values"], batches=two["batches"], iterations=iterations,
                V=vis, F=fs, G=gather, R=max(0.0, repeated), X=fixed, k=imbalance, rays=rays,
                ray_rate=rays / vis if vis > 0 else 0.0, exchange_mb=two["exchange_bytes"] / 1e6,
                exchange_s=two["exchange_seconds"], measured_1x2=one["seconds"], measured_2x1=two["seconds"])


def model(p, machines):
    stages = math.ceil(math.log2(machines)) if machines > 1 else 0
    exchange = p["batches"] * ALPHA * stages + BETA * p["values"] * 12 * (machines - 1) / machines
    k = p["k"] if machines > 1 else 1.0
    divisible = k * (p["V"] + p["F"] + p["G"]) / (CORES * machines)
    fixed = p["X0"] + (p["X"] - p["X0"]) / machines
    return fixed + divisible + p["iterations"] * (p["R"] + exchange) + exchange, exchange


def report(name, p):
    t1, _ = model(p, 1)
    print(f"{name}: {p['tixels']:,} tixels, {p['values']:,} values, {p['batches']} batches, {p['iterations']} iterations; "
          f"visibility {p['V']:.1f} core-s ({p['ray_rate'] / 1e6:.2f} Mrays/s per core), first shot {p['F']:.1f}, "
          f"gather {p['G']:.1f} core-s; repeated per iteration R {p['R']:.3f} s; X {p['X']:.1f} s of which X0 {p['X0']:.1f} s repeated; "
          f"imbalance k {p['k']:.3f}; model T(1) {t1:.1f} s")
    print(f"  {'machines':>8} {'T(M) s':>9} {'speed-up':>9} {'exchange/iter s':>16} {'repeated share':>15} "
          f"{'speed-up if X0, R were split':>29}")
    for m in MACHINES:
        t, exchange = model(p, m)
        serial = p["X0"] + p["iterations"] * p["R"]
        # What the speed-up would be if the repeated work (setup X0, per-iteration R) were
        # divided between the machines too: what sharding the parameterisation would buy.
        split = dict(p, X0=p["X0"] / m, R=p["R"] / m)
        t_split, _ = model(split, m)
        print(f"  {m:>8} {t:>9.1f} {t1 / t:>9.2f} {exchange:>16.4f} {serial / t:>15.0%} {t1 / t_split:>29.2f}")


def main(argv):
    if len(argv) < 3:
        print(__doc__)
        return 2
    one, two = load(argv[1]), load(argv[2])
    p = inputs(one, two)
    p["X0"] = p["X"] if FIXED is None else min(FIXED, p["X"])
    print(f"measured: 1x2 {p['measured_1x2']:.1f} s, 2x1 {p['measured_2x1']:.1f} s (ratio {p['measured_2x1'] / p['measured_1x2']:.3f}); "
          f"rank 0 received {p['exchange_mb']:.1f} MB in {two['exchanges']} exchanges, {p['exchange_s']:.2f} s inside them")
    report(f"{two['scene']} {two['preset']} (measured)", p)
    args = argv[3:]
    while args:
        if args[0] != "--scale" or len(args) < 7:
            print(__doc__)
            return 2
        name, tixels, dirs, values, iterations = args[1], int(args[2]), float(args[3]), int(args[4]), int(args[5])
        fixed = float(args[6])
        q = dict(p)
        ratio_t = tixels / p["tixels"]
        ratio_d = dirs / DIRS_MEASURED
        q.update(tixels=tixels, values=values, iterations=iterations, X0=fixed,
                 X=fixed + (p["X"] - p["X0"]) * ratio_t * ratio_d,
                 batches=max(1, min(16000, round(p["batches"] * ratio_t))),
                 V=p["V"] * ratio_t * ratio_d, F=p["F"] * ratio_t,
                 G=p["G"] / p["iterations"] * iterations * ratio_t * ratio_d,
                 R=p["R"] * values / p["values"])
        report(f"{name} (scaled from the measured run)", q)
        args = args[7:]
    return 0


DIRS_MEASURED = 256.0  # gather directions of the measured run (set with --dirs)
FIXED = None  # X0 (set with --fixed)

if __name__ == "__main__":
    if "--dirs" in sys.argv:
        i = sys.argv.index("--dirs")
        DIRS_MEASURED = float(sys.argv[i + 1])
        del sys.argv[i:i + 2]
    if "--fixed" in sys.argv:
        i = sys.argv.index("--fixed")
        FIXED = float(sys.argv[i + 1])
        del sys.argv[i:i + 2]
    sys.exit(main(sys.argv))
