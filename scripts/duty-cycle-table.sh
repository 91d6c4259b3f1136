#!/usr/bin/env bash
# The duty-cycled calibration table of docs/drift.md 4.6 on the independent gyro family
# (../shared/testdata/gyro_thermal_family): per unit, the thermal model fitted on an 8-h
# calibration logged 5 s of every 300 s (generate.py --bursts 5,300) with --gaps carry and with
# --gaps interpolate, and on the same unit's continuous 8-h calibration; each compensates the 8-h
# mission run (run 2), scored against its truth (% of the true drift's RMS removed).
# Usage: scripts/duty-cycle-table.sh [FIRST LAST]   (default units 1 20)
# WORK holds the logs (generated when missing, as b$U.csv, c8_$U.csv and m$U.csv with the
# mission's drift_dph beside it) and keeps them between runs. Needs /usr/bin/python3 with numpy
# to generate.
set -euo pipefail
first=${1:-1}; last=${2:-20}
top=$(cd "$(dirname "$0")/.." && pwd)
B=${GYRODRIFT:-$top/build/apps/gyrodrift/gyrodrift}
G=$top/../shared/testdata/gyro_thermal_family/generate.py
[ -x "$B" ] || { echo "duty-cycle-table.sh: no gyrodrift at $B (run make build first)" >&2; exit 2; }
work=${WORK:-$(mktemp -d)}
mkdir -p "$work"
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
echo "unit,continuous,carry,interpolate"
for u in $(seq "$first" "$last"); do
  if [ ! -f "$work/b$u.csv" ] || [ ! -f "$work/c8_$u.csv" ] || [ ! -f "$work/m$u.csv" ]; then
    /usr/bin/python3 -c 'import numpy' 2>/dev/null ||
      { echo "duty-cycle-table.sh: the family generator needs python3-numpy" >&2; exit 2; }
    /usr/bin/python3 "$G" "$u" 1 8 "$work/b$u.csv" "$out/t.csv" --style calibration --bursts 5,300
    /usr/bin/python3 "$G" "$u" 1 8 "$work/c8_$u.csv" "$out/t.csv" --style calibration
    /usr/bin/python3 "$G" "$u" 2 8 "$out/m.csv" "$out/t.csv" --style mission
    paste -d, "$out/m.csv" <(cut -d, -f2 "$out/t.csv") > "$work/m$u.csv"
  fi
  printf "%s" "$u"
  for case in continuous carry interpolate; do
    case $case in
      continuous) cal=$work/c8_$u.csv; gaps=error ;;
      *) cal=$work/b$u.csv; gaps=$case ;;
    esac
    "$B" fit "$cal" -t rate_dph -T temperature_c --mode compensate --gaps "$gaps" -q \
      -o "$out/m.json"
    removed=$("$B" compensate "$out/m.json" "$work/m$u.csv" --truth drift_dph -o "$out/c.csv" \
      | sed -n 's/.*(\(-*[0-9.]*\) % removed).*/\1/p')
    printf ",%s" "$removed"
  done
  printf "\n"
done
