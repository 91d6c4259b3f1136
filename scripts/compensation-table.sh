#!/usr/bin/env bash
# Reproduces the compensate-mode table of docs/drift.md section 4.1 with the CLI alone: for each
# (training programme, test programme) pair of 8-hour navigation-grade simulations, fit every
# method on the training run and report the share of the test run's true drift RMS it removes
# (`gyrodrift compensate --truth drift_dph`).
# Usage: scripts/compensation-table.sh [TRAIN_SEED TEST_SEED] (default 1 2); needs a build.
# FIT_ARGS adds fit options (docs/drift.md 4.5 uses FIT_ARGS="--reference-temperature 20", the
# simulator's truth convention); METHODS chooses the methods.
set -euo pipefail
cd "$(dirname "$0")/.."
bin=${GYRODRIFT:-build/apps/gyrodrift/gyrodrift}
train_seed=${1:-1}
test_seed=${2:-2}
methods=${METHODS:-thermal ms-elm emd-elm elm poly svr bp}
fit_args=${FIT_ARGS:-}
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
pairs=("chamber chamber-b" "chamber-b chamber" "chamber sine" "sine chamber-b")
printf '%-22s' "train -> test"
for m in $methods; do printf '%9s' "$m"; done
printf '\n'
for pair in "${pairs[@]}"; do
  read -r train test <<<"$pair"
  [[ -f $work/$train-$train_seed.csv ]] ||
    "$bin" simulate --profile "$train" --seed "$train_seed" -q -o "$work/$train-$train_seed.csv"
  [[ -f $work/$test-$test_seed.csv ]] ||
    "$bin" simulate --profile "$test" --seed "$test_seed" -q -o "$work/$test-$test_seed.csv"
  printf '%-22s' "$train -> $test"
  for m in $methods; do
    "$bin" fit "$work/$train-$train_seed.csv" -t rate_dph -T temperature_c --mode compensate \
      -m "$m" $fit_args -q -o "$work/model.json"
    removed=$("$bin" compensate "$work/model.json" "$work/$test-$test_seed.csv" \
      --truth drift_dph -o "$work/out.csv" | sed -n 's/.*(\(.*\) % removed).*/\1/p')
    printf '%9s' "$removed"
  done
  printf '\n'
done
