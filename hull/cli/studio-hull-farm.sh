#!/usr/bin/env bash
# studio-hull-farm.sh: a recorded take reconstructed on a render farm (issue 21; docs/offline.md).
# Splits the take into contiguous frame shards (studio-hull offline --plan N), submits them as one
# Slurm job array (sbatch --array, one `studio-hull offline ... --frames A:B` per task) and a
# dependent job that writes the sequence's index (--index-only) when every shard succeeded.
# --local runs exactly the same shard commands on this machine instead (P at a time), then the
# index. Shards are resumable and idempotent (frames already written and verified are skipped),
# so a failed or killed task is simply resubmitted (or the whole script run again).
set -euo pipefail

usage() {
  cat <<'TXT'
usage: studio-hull-farm.sh [--shards N] [--local [--parallel P]] [--hull PATH]
                           [--partition NAME] [--time HH:MM:SS] [--cpus C] [--log-dir DIR]
                           [--dry-run] -- STUDIO-HULL-OFFLINE-ARGS...

  STUDIO-HULL-OFFLINE-ARGS  the arguments of `studio-hull offline` for the whole take, without
                            --frames (e.g. --take takes/t1 --box ... --grid 512 --refine
                            --texture --out out/t1 --threads 2)
  --shards N        number of shards (default 4); each is a contiguous frame range
  --local           run the shard commands here instead of submitting them to Slurm
  --parallel P      --local: shards at a time (default 1)
  --hull PATH       the studio-hull binary (default: studio-hull on PATH)
  --partition, --time, --cpus   passed to sbatch (-p, -t, -c; default cpus: 2)
  --log-dir DIR     per-task logs (default ./studio-hull-farm-logs; never the output folder)
  --dry-run         print the commands (or the sbatch calls) without running them
Prints the Slurm job ids (array, then index) or, with --local, each shard's JSON summary.
Exit status: 0 submitted / done; 1 a shard or the index failed; 2 bad arguments.
TXT
}

shards=4 local=0 parallel=1 hull=studio-hull partition="" time_limit="" cpus=2
log_dir=./studio-hull-farm-logs dry=0
while [ $# -gt 0 ]; do
  case "$1" in
    -h|--help) usage; exit 0 ;;
    --shards) shards=$2; shift 2 ;;
    --local) local=1; shift ;;
    --parallel) parallel=$2; shift 2 ;;
    --hull) hull=$2; shift 2 ;;
    --partition) partition=$2; shift 2 ;;
    --time) time_limit=$2; shift 2 ;;
    --cpus) cpus=$2; shift 2 ;;
    --log-dir) log_dir=$2; shift 2 ;;
    --dry-run) dry=1; shift ;;
    --) shift; break ;;
    *) echo "studio-hull-farm: unknown option $1 (see --help)" >&2; exit 2 ;;
  esac
done
[ $# -gt 0 ] || { echo "studio-hull-farm: give the studio-hull offline arguments after --" >&2; exit 2; }
for a in "$@"; do
  [ "$a" != "--frames" ] || { echo "studio-hull-farm: --frames is chosen per shard; leave it out" >&2; exit 2; }
done
[[ "$shards" =~ ^[1-9][0-9]*$ ]] || { echo "studio-hull-farm: --shards: need N >= 1" >&2; exit 2; }
[[ "$parallel" =~ ^[1-9][0-9]*$ ]] || { echo "studio-hull-farm: --parallel: need P >= 1" >&2; exit 2; }
args=("$@")

ranges=$("$hull" offline "${args[@]}" --plan "$shards") || exit 2
mapfile -t range_list <<<"$ranges"
mkdir -p "$log_dir"
quoted=$(printf '%q ' "$hull" offline "${args[@]}")

if [ "$local" -eq 1 ]; then
  run_shard() {  # $1 = A:B
    local cmd="$quoted --frames $1 --json"
    if [ "$dry" -eq 1 ]; then echo "$cmd"; return 0; fi
    eval "$cmd" >"$log_dir/shard-${1/:/-}.json" 2>"$log_dir/shard-${1/:/-}.err" ||
      { echo "studio-hull-farm: shard $1 failed: $(tail -n1 "$log_dir/shard-${1/:/-}.err")" >&2; return 1; }
    tail -n1 "$log_dir/shard-${1/:/-}.json"
  }
  status=0
  running=0
  pids=()
  for r in "${range_list[@]}"; do
    run_shard "$r" & pids+=($!)
    running=$((running + 1))
    if [ "$running" -ge "$parallel" ]; then
      wait "${pids[0]}" || status=1
      pids=("${pids[@]:1}")
      running=$((running - 1))
    fi
  done
  for p in "${pids[@]}"; do wait "$p" || status=1; done
  [ "$status" -eq 0 ] || exit 1
  if [ "$dry" -eq 1 ]; then echo "$quoted --index-only"; exit 0; fi
  eval "$quoted --index-only" || exit 1
  exit 0
fi

sb=(sbatch --parsable -c "$cpus" -J studio-hull-offline)
[ -z "$partition" ] || sb+=(-p "$partition")
[ -z "$time_limit" ] || sb+=(-t "$time_limit")
# The array task picks its range by SLURM_ARRAY_TASK_ID (POSIX sh: sbatch --wrap runs /bin/sh).
task_script="set -- ${range_list[*]}; shift \$SLURM_ARRAY_TASK_ID; exec $quoted --frames \$1 --json"
array_cmd=("${sb[@]}" --array "0-$((${#range_list[@]} - 1))" -o "$log_dir/task-%A_%a.json" -e "$log_dir/task-%A_%a.err" --wrap "$task_script")
if [ "$dry" -eq 1 ]; then printf '%q ' "${array_cmd[@]}"; echo; exit 0; fi
command -v sbatch >/dev/null || { echo "studio-hull-farm: sbatch not found (install slurm-client, or use --local)" >&2; exit 2; }
array_id=$("${array_cmd[@]}") || exit 1
index_id=$("${sb[@]}" --dependency "afterok:${array_id%%;*}" -o "$log_dir/index-%j.log" --wrap "$quoted --index-only") || exit 1
echo "array ${array_id%%;*}"
echo "index ${index_id%%;*}"
