#!/usr/bin/env bash
# Runs `clearway bench` on a Slurm cluster: N array tasks (one shard each), then a merge job that waits
# for all of them (afterok) and writes OUT_DIR/{results,summary}.csv, table.txt and the plots, the same
# files as one unsharded run.
# Usage: benchmarks/slurm/submit.sh N OUT_DIR [clearway bench arguments...]   (prints the merge job id)
# Set CLEARWAY to the clearway binary when it is not on PATH; extra sbatch options in SBATCH_OPTIONS.
set -euo pipefail
n=${1:?usage: submit.sh N OUT_DIR [bench arguments...]}
out=${2:?usage: submit.sh N OUT_DIR [bench arguments...]}
shift 2
case "$n" in '' | *[!0-9]* | 0) echo "submit.sh: N must be a positive integer, got '$n'" >&2; exit 2 ;; esac
here=$(cd "$(dirname "$0")" && pwd)
clearway=${CLEARWAY:-$(command -v clearway || true)}
[ -x "$clearway" ] || { echo "submit.sh: no clearway binary (set CLEARWAY)" >&2; exit 2; }
mkdir -p "$out"
out=$(cd "$out" && pwd)
array=$(CLEARWAY="$clearway" sbatch --parsable ${SBATCH_OPTIONS:-} --chdir "$out" --export=ALL \
  --array="0-$((n - 1))" "$here/bench_array.sbatch" "$out" "$@")
shards=""
for ((i = 0; i < n; ++i)); do shards="$shards '$out/shard-$i'"; done
sbatch --parsable ${SBATCH_OPTIONS:-} --chdir "$out" --job-name=clearway-bench-merge --dependency="afterok:$array" \
  --output="$out/merge.log" --wrap "'$clearway' bench merge --out '$out'$shards"
