#!/usr/bin/env bash
# How a calibration log with a hole is best used (docs/drift.md 4.6), on the independent gyro
# family (../shared/testdata/gyro_thermal_family): per unit, the 16-h calibration run (run 1) loses
# hours CUT_FROM..CUT_TO (the logger stopped), and the model is fitted
#   full:        on the whole run (no hole: the reference),
#   split:       --gaps split (two records, the thermal states restarting after the hole; the
#                same model as fitting the two pieces as two logs),
#   interpolate: --gaps interpolate (the hole filled linearly in every column),
#   longest:     on the longest piece alone,
# then compensates the 8-h mission run (run 2) and scores it against its truth (% of the drift
# RMS removed). Usage: scripts/records-table.sh [FIRST LAST [CUT_FROM CUT_TO]] (default 1 20 6 8)
set -euo pipefail
first=${1:-1}; last=${2:-20}; cut_from=${3:-6}; cut_to=${4:-8}
top=$(cd "$(dirname "$0")/.." && pwd)
B=${GYRODRIFT:-$top/build/apps/gyrodrift/gyrodrift}
G=$top/../shared/testdata/gyro_thermal_family/generate.py
if ! /usr/bin/python3 -c 'import numpy' 2>/dev/null; then
  echo "records-table.sh: the family generator needs Debian's python3-numpy" >&2
  exit 2
fi
[ -x "$B" ] || { echo "records-table.sh: no gyrodrift at $B (run make build first)" >&2; exit 2; }
work=${WORK:-$(mktemp -d)}
mkdir -p "$work"
echo "unit,full,split,interpolate,longest"
for u in $(seq "$first" "$last"); do
  train=$work/u${u}_train16.csv; test=$work/u${u}_test.csv
  [ -f "$train" ] || /usr/bin/python3 "$G" "$u" 1 16 "$train" "$work/u${u}_train16_truth.csv" --style calibration
  if [ ! -f "$test" ]; then
    /usr/bin/python3 "$G" "$u" 2 8 "$work/u${u}_test_raw.csv" "$work/u${u}_test_truth.csv" --style mission
    paste -d, "$work/u${u}_test_raw.csv" <(cut -d, -f2 "$work/u${u}_test_truth.csv") > "$test"
  fi
  # The hole: rows whose time_s lies in [cut_from, cut_to) hours; the longest piece beside it.
  awk -F, -v a=$((cut_from * 3600)) -v b=$((cut_to * 3600)) 'NR == 1 || $1 < a || $1 >= b' "$train" > "$work/u${u}_hole.csv"
  before=$((cut_from * 3600)); after=$((16 * 3600 - cut_to * 3600))
  if [ "$before" -ge "$after" ]; then
    awk -F, -v a=$((cut_from * 3600)) 'NR == 1 || $1 < a' "$train" > "$work/u${u}_longest.csv"
  else
    awk -F, -v b=$((cut_to * 3600)) 'NR == 1 || $1 >= b' "$train" > "$work/u${u}_longest.csv"
  fi
  printf "%s" "$u"
  for variant in full split interpolate longest; do
    case $variant in
      full) args=("$train") ;;
      split) args=("$work/u${u}_hole.csv" --gaps split) ;;
      interpolate) args=("$work/u${u}_hole.csv" --gaps interpolate) ;;
      longest) args=("$work/u${u}_longest.csv") ;;
    esac
    "$B" fit "${args[@]}" -t rate_dph -T temperature_c --mode compensate -q -o "$work/m_${u}_$variant.json"
    removed=$("$B" compensate "$work/m_${u}_$variant.json" "$test" --truth drift_dph -o "$work/c_${u}_$variant.csv" \
      | sed -n 's/.*(\(-*[0-9.]*\) % removed).*/\1/p')
    printf ",%s" "$removed"
  done
  printf "\n"
done
