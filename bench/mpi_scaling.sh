#!/usr/bin/env bash
# Strong scaling of the distributed bake on one machine (issue #16): the same bake as
#   1 rank × 2 threads:   plenoptic bake SCENE --threads 2
#   2 ranks × 1 thread:   mpirun -np 2 plenoptic bake SCENE --threads 1
# (the same two cores either way: what the second costs over the first is the exchange and
# the work every rank repeats), checks that both light fields render to the same bits, and
# prints one row per scene: wall seconds of each, their ratio, the CPU seconds (user + system,
# /usr/bin/time; on a machine shared with other work the CPU time is the steadier figure, and
# Open MPI's ranks poll while they wait in an exchange, so waiting counts in it as it would in
# wall time on idle cores), the exchange (MB received per rank, number of allgatherv calls,
# seconds inside them). The --stats JSON of every run stays in WORKDIR (NAME.1x2.json,
# NAME.2x1.json): bench/mpi_model.py turns them into the modelled speed-up on 4, 16 and 64
# machines.
#
# Usage: bench/mpi_scaling.sh [PLENOPTIC] [WORKDIR]
#   PLENOPTIC  the executable (default: build/plenoptic)
#   WORKDIR    where every file goes (default: out/mpi)
# Environment: RUNS, space-separated NAME=SCENE:PRESET items (default: the built-in Cornell
# box at the high preset; add e.g. sponza=/work/shared/scenes/sponza/sponza.json:default).
# Every run deletes its .plv files after it (a Sponza default field is ~4 GB).
set -euo pipefail

PLENOPTIC="${1:-build/plenoptic}"
WORKDIR="${2:-out/mpi}"
RUNS="${RUNS:-cornell=cornell:high}"
mkdir -p "$WORKDIR"
command -v mpirun >/dev/null || { echo "mpi_scaling: mpirun not found (scripts/bootstrap.sh installs openmpi-bin)" >&2; exit 1; }
# --bind-to none: Open MPI binds each of 2 ranks to a core by default, and a rank whose core
# another program (a build, a test) holds cannot move; the 1-rank run is not bound either.
MPIRUN=(mpirun --oversubscribe --allow-run-as-root --bind-to none)

json() { python3 -c "import json,sys; d=json.load(open(sys.argv[1])); print(eval(sys.argv[2], {}, d))" "$@"; }

printf '%-10s %-8s %9s %9s %6s %9s %9s %6s %9s %6s %8s %s\n' scene preset "1x2 s" "2x1 s" ratio "1x2 cpu" "2x1 cpu" ratio \
  "exch MB" calls "exch s" "same bits"
for item in $RUNS; do
  name="${item%%=*}"; rest="${item#*=}"; scene="${rest%%:*}"; preset="${rest##*:}"
  one="$WORKDIR/$name.1x2"; two="$WORKDIR/$name.2x1"
  /usr/bin/time -f '%U %S' -o "$one.cpu" \
    "$PLENOPTIC" bake "$scene" -o "$one.plf" --preset "$preset" --threads 2 --quiet --stats "$one.json" > "$one.log" 2>&1
  rm -f "$one.plv"
  /usr/bin/time -f '%U %S' -o "$two.cpu" "${MPIRUN[@]}" -np 2 "$PLENOPTIC" bake "$scene" -o "$two.plf" --preset "$preset" --threads 1 --quiet \
    --stats "$two.json" > "$two.log" 2>&1
  rm -f "$two".rank*-of-2.plv
  # Same light field: the fast renderer's image of each, compared bit for bit.
  "$PLENOPTIC" render "$one.plf" -o "$one.pfm" --quiet > /dev/null 2>&1
  "$PLENOPTIC" render "$two.plf" -o "$two.pfm" --quiet > /dev/null 2>&1
  same=$(cmp -s "$one.pfm" "$two.pfm" && echo yes || echo NO)
  t1=$(json "$one.json" seconds); t2=$(json "$two.json" seconds)
  c1=$(awk '{print $1 + $2}' "$one.cpu"); c2=$(awk '{print $1 + $2}' "$two.cpu")
  printf '%-10s %-8s %9.2f %9.2f %6.3f %9.2f %9.2f %6.3f %9.1f %6d %8.2f %s\n' "$name" "$preset" "$t1" "$t2" \
    "$(python3 -c "print($t2/$t1)")" "$c1" "$c2" "$(python3 -c "print($c2/$c1)")" \
    "$(json "$two.json" 'exchange_bytes/1e6')" "$(json "$two.json" exchanges)" "$(json "$two.json" exchange_seconds)" "$same"
done
