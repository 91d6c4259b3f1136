#!/usr/bin/env bash
# The compensation table of docs/drift.md 4.5 on the independent gyro family
# (../shared/testdata/gyro_thermal_family): per unit, fit on the calibration run (run 1), compensate
# the 8-h mission run (run 2), score against its truth. Needs /usr/bin/python3 with numpy to
# generate the units. Usage: scripts/family-table.sh [FIRST LAST [HOURS [METHODS]]]
#   FIRST LAST  units (default 1 20); HOURS calibration length (default 16)
#   METHODS     comma-separated fit methods (default thermal,poly; ms-elm takes about 8 s a unit)
# FIT_ARGS adds fit options to the identified methods (thermal, ms-elm, emd-elm), for example
# FIT_ARGS="--hysteresis off" (docs/drift.md 4.7); WORK keeps the generated units between runs.
set -euo pipefail
first=${1:-1}; last=${2:-20}; hours=${3:-16}; methods=${4:-thermal,poly}; fit_args=${FIT_ARGS:-}
top=$(cd "$(dirname "$0")/.." && pwd)
B=${GYRODRIFT:-$top/build/apps/gyrodrift/gyrodrift}
G=$top/../shared/testdata/gyro_thermal_family/generate.py
if ! /usr/bin/python3 -c 'import numpy' 2>/dev/null; then
  echo "family-table.sh: the family generator needs Debian's python3-numpy (apt-get install python3-numpy)" >&2
  exit 2
fi
[ -x "$B" ] || { echo "family-table.sh: no gyrodrift at $B (run make build first)" >&2; exit 2; }
work=${WORK:-$(mktemp -d)}
mkdir -p "$work"
printf "unit"; for m in ${methods//,/ }; do printf ",%s" "$m"; done; printf "\n"
for u in $(seq "$first" "$last"); do
  train=$work/u${u}_train${hours}.csv; test=$work/u${u}_test.csv
  [ -f "$train" ] || /usr/bin/python3 "$G" "$u" 1 "$hours" "$train" "$work/u${u}_train${hours}_truth.csv" --style calibration
  if [ ! -f "$test" ]; then
    /usr/bin/python3 "$G" "$u" 2 8 "$work/u${u}_test_raw.csv" "$work/u${u}_test_truth.csv" --style mission
    # The truth's drift_dph beside the log, for --truth.
    paste -d, "$work/u${u}_test_raw.csv" <(cut -d, -f2 "$work/u${u}_test_truth.csv") > "$test"
  fi
  printf "%s" "$u"
  for m in ${methods//,/ }; do
    extra=""
    case $m in thermal|ms-elm|emd-elm) extra=$fit_args ;; esac
    # shellcheck disable=SC2086
    "$B" fit "$train" -t rate_dph -T temperature_c --mode compensate -m "$m" $extra -q \
      -o "$work/m_${u}_$m.json"
    removed=$("$B" compensate "$work/m_${u}_$m.json" "$test" --truth drift_dph -o "$work/c_${u}_$m.csv" \
      | sed -n 's/.*(\(-*[0-9.]*\) % removed).*/\1/p')
    printf ",%s" "$removed"
  done
  printf "\n"
done
