#!/usr/bin/env bash
# Slurm job-array template: one experiment split into N shards, one array task
# per shard, then one merge job (docs/experiments.md, "Beyond one machine").
#
#   CONFIG=experiments/thesis-bluepaint.toml OUT=results/thesis-bluepaint N=8 \
#     sbatch --array=1-8 experiments/slurm-array.sh
#   # when all tasks are done (or chain it: sbatch --dependency=afterok:<jobid> ...):
#   brdf-factor merge results/thesis-bluepaint/shard-*-of-8 --out results/thesis-bluepaint
#
# Each task runs `brdf-factor run --shard K/N`, which executes a deterministic
# 1/N of the runs (run i when i mod N = K-1) into OUT/shard-K-of-N. A task
# that is killed or times out leaves its unfinished run folders without a DONE
# marker; resubmitting the same array index redoes only those. merge refuses
# to collate while any planned run is missing or duplicated.
#
# Adjust to your cluster: partition, time, memory. A search parallelizes its
# restarts over the task's cores (cpus-per-task); serial runs fill them too.
#SBATCH --job-name=brdf-factor
#SBATCH --cpus-per-task=4
#SBATCH --mem=8G
#SBATCH --time=04:00:00
#SBATCH --output=slurm-%A_%a.out

set -euo pipefail

: "${CONFIG:?set CONFIG to the experiment config (TOML)}"
: "${OUT:?set OUT to the experiment folder (shards go to OUT/shard-K-of-N)}"
: "${N:?set N to the number of shards (= the array size)}"
K="${SLURM_ARRAY_TASK_ID:?run as an array job: sbatch --array=1-N}"
BRDF_FACTOR="${BRDF_FACTOR:-brdf-factor}"   # path of the executable if not on PATH

# Extra overrides, e.g. DEFINES="-D sampling.resolution=12 -D method.restarts=3"
# shellcheck disable=SC2086
exec "$BRDF_FACTOR" run "$CONFIG" --shard "$K/$N" --out "$OUT/shard-$K-of-$N" \
  --jobs "${SLURM_CPUS_PER_TASK:-0}" --no-plots ${DEFINES:-}
