#!/usr/bin/env python3
"""Modelled speed-up of the distributed bake on M machines (issue #16), from measured inputs.

Inputs: the --stats JSON of a 1 rank × 2 threads bake and of the same bake as 2 ranks × 1
thread (bench/mpi_scaling.sh writes NAME.1x2.json and NAME.2x1.json). From them:

  rays/core-s   visibility rays per second per core (Σ rank rays / Σ rank visibility seconds)
  P             core-seconds of the per-tixel setup of the parameterisation (footprints and
                buried-point probes; Σ of the 2x1 run's rank_tixel_setup_seconds), divided
                between the ranks (shard.h fillTixelsDistributed)
  V, F, G       core-seconds of the divisible work: visibility, first shot, gather (Σ over
                ranks of rank_visibility_seconds and rank_gather_seconds; F = ranks × the
                smallest rank_first_shot_seconds, which include the wait at the first exchange)
  R             per iteration, the work every rank repeats for all tixels (transport refresh,
                change, power sums; rank 0's rank_repeated_seconds / iterations)
  X0            the setup every rank repeats: loading the scene (load_seconds) and the BVH and
                charts (setup_seconds), both from the 2x1 run (1 thread: conservative, the BVH
                build is multi-threaded)
  W             the rest of the 1x2 run: seconds − load − setup − tixel setup − visibility −
                propagation: writing the .plv, which each rank does for its own shard (/ M), and
                the .plf (rank 0; counted / M too, it is a few seconds)
  B, I, bytes   batches (one allgatherv each per iteration), iterations, values × 12 bytes;
                the setup's exchange moves 40 bytes per tixel in 4 allgathervs

Model, M machines like this one (C = 2 cores each), one rank per machine:

  T(M) = X0 + W/M + k·(P + V + F + G)/(C·M) + setup exchange + (I + 1)·exchange(M) + I·R
  exchange(M) = B·α·⌈log2 M⌉ + β·values·12·(M−1)/M

  k      load imbalance of the divisible work, measured at 2 ranks (max/mean of the ranks'
         tixel setup + visibility + gather seconds), assumed to hold at M
  α      latency of one allgatherv stage, 50 µs (10 GbE, recursive doubling: ⌈log2 M⌉ stages)
  β      1 / (1 GB/s) per byte received (10 GbE; an allgather receives (M−1)/M of the values)
  R      conservatively not divided by the threads (it was measured with 1 thread)

Speed-up S(M) = T(1) / T(M). `--scale NAME TIXELS DIRS VALUES ITER SETUP P` models another preset of
the same scene from the measured one: visibility, gather and the .plv write ∝ tixels × directions,
first shot ∝ tixels, R and the exchange ∝ values, batches ∝ tixels (≤ 16000); SETUP (seconds of
BVH and charts) and P (core-seconds of the per-tixel setup) measured for that preset (the
"parameterisation:" line of `plenoptic bake` prints both), loading as measured.

Usage: bench/mpi_model.py ONE_X_TWO.json TWO_X_ONE.json [--dirs N] [--scale NAME TIXELS DIRS VALUES ITERATIONS SETUP P]...
  --dirs N   gather directions of the measured runs (default 256, the default preset)
"""
import json
import math
import sys

ALPHA = 50e-6  # s per allgatherv stage
BETA = 1.0 / 1.0e9  # s per byte
CORES = 2
MACHINES = [1, 4, 16, 64]
SETUP_BYTES_PER_TIXEL = 40  # gather point, gather normal, transport albedo (3 floats each), coverage
SETUP_EXCHANGES = 4


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
    tixel_setup = sum(two["rank_tixel_setup_seconds"])
    rays = sum(two["rank_visibility_rays"])
    per_rank = [two["rank_tixel_setup_seconds"][r] + two["rank_visibility_seconds"][r] + two["rank_gather_seconds"][r]
                for r in range(ranks)]
    imbalance = max(per_rank) / (sum(per_rank) / ranks)
    iterations = two["iterations"]
    repeated = two["rank_repeated_seconds"][0] / iterations
    repeated_setup = two["load_seconds"] + two["setup_seconds"]
    rest = (one["seconds"] - one["load_seconds"] - one["setup_seconds"] - one["rank_tixel_setup_seconds"][0] -
            one["visibility_seconds"] - one["propagation_seconds"])
    return dict(tixels=two["tixels"], values=two["values"], batches=two["batches"], iterations=iterations,
                P=tixel_setup, V=vis, F=fs, G=gather, R=max(0.0, repeated), X0=repeated_setup, W=max(0.0, rest),
                load=two["load_seconds"], setup=two["setup_seconds"], k=imbalance, rays=rays,
                ray_rate=rays / vis if vis > 0 else 0.0, exchange_mb=two["exchange_bytes"] / 1e6,
                exchange_s=two["exchange_seconds"], measured_1x2=one["seconds"], measured_2x1=two["seconds"],
                tixel_setup_split=[round(s, 1) for s in two["rank_tixel_setup_seconds"]])


def model(p, machines):
    stages = math.ceil(math.log2(machines)) if machines > 1 else 0
    exchange = p["batches"] * ALPHA * stages + BETA * p["values"] * 12 * (machines - 1) / machines
    setup_exchange = SETUP_EXCHANGES * ALPHA * stages + BETA * p["tixels"] * SETUP_BYTES_PER_TIXEL * (machines - 1) / machines
    k = p["k"] if machines > 1 else 1.0
    divisible = k * (p["P"] + p["V"] + p["F"] + p["G"]) / (CORES * machines)
    fixed = p["X0"] + p["W"] / machines + setup_exchange
    return fixed + divisible + p["iterations"] * (p["R"] + exchange) + exchange, exchange


def report(name, p):
    t1, _ = model(p, 1)
    print(f"{name}: {p['tixels']:,} tixels, {p['values']:,} values, {p['batches']} batches, {p['iterations']} iterations; "
          f"tixel setup P {p['P']:.1f} core-s, visibility {p['V']:.1f} core-s ({p['ray_rate'] / 1e6:.2f} Mrays/s per core), "
          f"first shot {p['F']:.1f}, gather {p['G']:.1f} core-s; repeated: setup X0 {p['X0']:.1f} s (load {p['load']:.1f}, "
          f"BVH and charts {p['setup']:.1f}), per iteration R {p['R']:.3f} s; writes W {p['W']:.1f} s; "
          f"imbalance k {p['k']:.3f}; model T(1) {t1:.1f} s")
    print(f"  {'machines':>8} {'T(M) s':>9} {'speed-up':>9} {'exchange/iter s':>16} {'repeated share':>15} "
          f"{'speed-up if R were split':>25}")
    for m in MACHINES:
        t, exchange = model(p, m)
        serial = p["X0"] + p["iterations"] * p["R"]
        # What dividing the per-iteration pass every rank repeats (R) would still buy.
        t_split, _ = model(dict(p, R=p["R"] / m), m)
        print(f"  {m:>8} {t:>9.1f} {t1 / t:>9.2f} {exchange:>16.4f} {serial / t:>15.0%} {t1 / t_split:>25.2f}")


def main(argv):
    if len(argv) < 3:
        print(__doc__)
        return 2
    one, two = load(argv[1]), load(argv[2])
    p = inputs(one, two)
    print(f"measured: 1x2 {p['measured_1x2']:.1f} s, 2x1 {p['measured_2x1']:.1f} s (ratio {p['measured_2x1'] / p['measured_1x2']:.3f}); "
          f"rank 0 received {p['exchange_mb']:.1f} MB in {two['exchanges']} exchanges, {p['exchange_s']:.2f} s inside them; "
          f"tixel setup per rank {p['tixel_setup_split']} s")
    report(f"{two['scene']} {two['preset']} (measured)", p)
    args = argv[3:]
    while args:
        if args[0] != "--scale" or len(args) < 8:
            print(__doc__)
            return 2
        name, tixels, dirs, values, iterations = args[1], int(args[2]), float(args[3]), int(args[4]), int(args[5])
        setup, tixel_setup = float(args[6]), float(args[7])
        q = dict(p)
        ratio_t = tixels / p["tixels"]
        ratio_d = dirs / DIRS_MEASURED
        q.update(tixels=tixels, values=values, iterations=iterations, setup=setup, X0=p["load"] + setup, P=tixel_setup,
                 W=p["W"] * ratio_t * ratio_d,
                 batches=max(1, min(16000, round(p["batches"] * ratio_t))),
                 V=p["V"] * ratio_t * ratio_d, F=p["F"] * ratio_t,
                 G=p["G"] / p["iterations"] * iterations * ratio_t * ratio_d,
                 R=p["R"] * values / p["values"])
        report(f"{name} (scaled from the measured run)", q)
        args = args[8:]
    return 0


DIRS_MEASURED = 256.0  # gather directions of the measured run (set with --dirs)

if __name__ == "__main__":
    if "--dirs" in sys.argv:
        i = sys.argv.index("--dirs")
        DIRS_MEASURED = float(sys.argv[i + 1])
        del sys.argv[i:i + 2]
    sys.exit(main(sys.argv))
