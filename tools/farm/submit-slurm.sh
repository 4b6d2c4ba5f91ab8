#!/usr/bin/env bash
# Submits a whole dvr eval to Slurm: the references as an array of N tasks, then the
# scenes as an array of at most N tasks once every reference task succeeded, then the
# merge that writes the reports.
#
#   tools/farm/submit-slurm.sh 16 --scene suite --size 256x256 --out /shared/eval
#
# Extra sbatch options (a partition, an account) go in SBATCH_* variables, which sbatch
# reads itself: SBATCH_PARTITION=gpu SBATCH_ACCOUNT=lab tools/farm/submit-slurm.sh ...
set -euo pipefail
n="${1:?usage: submit-slurm.sh SHARDS DVR_EVAL_OPTIONS...}"
shift
here="$(cd "$(dirname "$0")" && pwd)"
refs=$(sbatch --parsable --array="0-$((n - 1))" "$here/dvr.sbatch" references "$@")
scenes=$(sbatch --parsable --array="0-$((n - 1))" --dependency="afterok:$refs" \
    "$here/dvr.sbatch" scenes "$@")
merge=$(sbatch --parsable --job-name=dvr-merge --dependency="afterok:$scenes" \
    --output=dvr-merge-%j.log --wrap "$(printf '%q ' "${DVR:-dvr}" eval --merge "$@")")
echo "submitted: references $refs, scenes $scenes, merge $merge"
