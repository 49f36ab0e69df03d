#!/usr/bin/env bash
# Renders SCENE as N tiles on a Slurm cluster and merges them: submits render-tiles.sbatch as
# an array of N tasks and merge.sbatch with a dependency on the whole array (afterok: it starts
# only when every tile succeeded, and is cancelled if one fails). Prints the two job ids as
# `tiles=ID merge=ID`. Paths must be on a file system every node sees.
#
# Usage: bash scripts/slurm/submit-tiles.sh N SCENE OUTPUT [raytree render options]
#   e.g. RAYTREE=$PWD/target/release/raytree bash scripts/slurm/submit-tiles.sh 16 default \
#          poster.png --width 16384 --height 16384 --samples 64
# PARTS_DIR: where the tiles and the jobs' logs go (default: OUTPUT's folder/OUTPUT.parts).
# SBATCH_ARGS: more sbatch options for both jobs (e.g. "--partition=render --cpus-per-task=8").
set -euo pipefail
here="$(cd "$(dirname "$0")" && pwd)"
usage="usage: submit-tiles.sh N SCENE OUTPUT [raytree render options]"
n="${1:?$usage}"
scene="${2:?$usage}"
output="${3:?$usage}"
shift 3
[[ "$n" =~ ^[1-9][0-9]*$ ]] || { echo "submit-tiles: N must be a whole number from 1, got $n" >&2; exit 1; }
mkdir -p "$(dirname "$output")"
output="$(cd "$(dirname "$output")" && pwd)/$(basename "$output")"
parts="${PARTS_DIR:-$output.parts}"
mkdir -p "$parts"
parts="$(cd "$parts" && pwd)"
# A scene file given by a relative path: absolute, for the nodes.
if [ -f "$scene" ]; then scene="$(cd "$(dirname "$scene")" && pwd)/$(basename "$scene")"; fi
# shellcheck disable=SC2086
tiles=$(sbatch --parsable ${SBATCH_ARGS:-} --array="0-$((n - 1))" \
  --output="$parts/slurm-%A_%a.out" "$here/render-tiles.sbatch" "$scene" "$parts" "$@")
tiles="${tiles%%;*}"
# shellcheck disable=SC2086
merge=$(sbatch --parsable ${SBATCH_ARGS:-} --dependency="afterok:$tiles" --kill-on-invalid-dep=yes \
  --output="$parts/slurm-merge-%j.out" "$here/merge.sbatch" "$parts" "$n" "$output")
merge="${merge%%;*}"
echo "tiles=$tiles merge=$merge"
