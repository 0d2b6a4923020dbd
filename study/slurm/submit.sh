#!/usr/bin/env bash
# Submits a sharded `rvr study` to Slurm: a job array of N tasks, task I running
# `rvr study --shard I/N ... -o OUT/shard-I` (rvr-study.sbatch), and a merge job that starts once
# every task has succeeded (--dependency=afterok) and runs
# `rvr study --merge OUT/shard-0 ... OUT/shard-(N-1) -o OUT/merged` (merge.sbatch).
#
# Usage: submit.sh N OUT RVR [STUDY_OPTION...]
#   N             number of shards, 1 or more (one array task each)
#   OUT           output folder, on a file system every node shares; created if missing, and
#                 refused if it already holds shards or a merged study (they would be merged)
#   RVR           the rvr binary, at a path every node can run it from
#   STUDY_OPTION  passed to every shard's `rvr study` (families, -r, --width, --mode, --budget,
#                 --repetitions, --seed); not -o, --shard or --merge, which the scripts set
#
# sbatch options (partition, node type, time limit, account) come from sbatch's own input
# environment variables, e.g. SBATCH_PARTITION, SBATCH_CONSTRAINT, SBATCH_TIMELIMIT,
# SBATCH_ACCOUNT; they apply to both jobs. Each shard asks for a whole node (--exclusive in
# rvr-study.sbatch) so that nothing else runs beside the timed frames.
#
# Standard output: one line, "ARRAY_JOB_ID MERGE_JOB_ID"; everything else goes to stderr.
# Logs: OUT/logs/shard-I.out and OUT/logs/merge.out.
set -euo pipefail

me=submit.sh
die() {
  echo "$me: error: $*" >&2
  exit 2
}
usage() {
  echo "usage: $me N OUT RVR [STUDY_OPTION...]  (see the comment at the top of $0)" >&2
  exit 2
}

[ $# -ge 3 ] || usage
shards=$1
out=$2
rvr=$3
shift 3

[[ $shards =~ ^[1-9][0-9]*$ ]] || die "N must be a whole number of shards, 1 or more (got '$shards')"
for option in "$@"; do
  case $option in
    -o | --output | --output=* | -o?* | --shard | --shard=* | --merge | --merge=*)
      die "'$option' is set by the scripts (task I runs --shard I/N -o OUT/shard-I; the merge job --merge ... -o OUT/merged)" ;;
  esac
done

command -v sbatch > /dev/null || die "sbatch not found: run this where Slurm's commands are installed (a login node)"

here=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd -P)
for script in rvr-study.sbatch merge.sbatch; do
  [ -r "$here/$script" ] || die "$here/$script is missing"
done

# The jobs run elsewhere, from another working directory: absolute paths only.
if [[ $rvr != */* ]]; then
  found=$(command -v "$rvr") || die "'$rvr' is not a command on PATH"
  rvr=$found
fi
if [ ! -f "$rvr" ] || [ ! -x "$rvr" ]; then
  die "$rvr is not an executable file"
fi
rvr=$(cd "$(dirname "$rvr")" && pwd -P)/$(basename "$rvr")

mkdir -p "$out" || die "cannot create $out"
out=$(cd "$out" && pwd -P)
shopt -s nullglob
stale=("$out"/shard-* "$out"/merged)
shopt -u nullglob
for path in "${stale[@]}"; do
  if [ -e "$path" ]; then
    die "$out already holds $(basename "$path"): choose another output folder, so that no earlier result is merged or overwritten"
  fi
done
mkdir -p "$out/logs"

last=$((shards - 1))
array_id=$(sbatch --parsable --array="0-$last" --chdir="$out" --output="$out/logs/shard-%a.out" \
  "$here/rvr-study.sbatch" "$out" "$shards" "$rvr" "$@") || die "sbatch refused the shards' job array"
array_id=${array_id%%;*}
# --kill-on-invalid-dep: when a shard fails the merge job is cancelled, not left pending.
merge_id=$(sbatch --parsable --dependency="afterok:$array_id" --kill-on-invalid-dep=yes \
  --chdir="$out" --output="$out/logs/merge.out" \
  "$here/merge.sbatch" "$out" "$shards" "$rvr") || {
  scancel "$array_id" || true
  die "sbatch refused the merge job (the shards' job array $array_id is cancelled)"
}
merge_id=${merge_id%%;*}

{
  echo "$me: shards: job array $array_id (tasks 0-$last) into $out/shard-0 ... $out/shard-$last"
  echo "$me: merge: job $merge_id, once every shard has succeeded, into $out/merged"
  echo "$me: logs in $out/logs; follow with: squeue -j $array_id,$merge_id"
} >&2
echo "$array_id $merge_id"
