#!/usr/bin/env bash
# Do two builds of fricsim write the same files? For changes meant to move
# no figure (a refactor): every example system run to CSV and to MAT, the
# EMPS diagnosis on one record and on both, and (with --suite) every case of
# the independent hidden-effect suite, each compared byte for byte.
#
# Usage: scripts/compare-builds.sh OLD_FRICSIM NEW_FRICSIM [--suite] [--out DIR]
#   OLD_FRICSIM, NEW_FRICSIM: two fricsim binaries (keep a copy of the old
#   one before rebuilding: cp target/release/fricsim /tmp/fricsim-old).
# Exits 1 and lists the files that differ when any does.
set -euo pipefail
cd "$(dirname "$0")/.."
[ $# -ge 2 ] || { sed -n '2,9p' "$0"; exit 2; }
old=$(realpath "$1") new=$(realpath "$2"); shift 2
suite=0 out=out/compare-builds
while [ $# -gt 0 ]; do
  case "$1" in
    --suite) suite=1 ;;
    --out) out="$2"; shift ;;
    *) echo "unknown argument: $1" >&2; exit 2 ;;
  esac
  shift
done
rm -rf "$out"; mkdir -p "$out/old" "$out/new"

outputs() { # BINARY DIR
  local bin=$1 dir=$2
  for ssd in examples/*.ssd; do
    name=$(basename "$ssd" .ssd)
    "$bin" run "$ssd" --out "$dir/$name.csv" >/dev/null
    "$bin" run "$ssd" --out "$dir/$name.mat" >/dev/null
  done
  "$bin" diagnose examples/emps_nominal.ssd examples/data/emps_train.csv \
    --out "$dir/emps-one" >/dev/null 2>&1
  "$bin" diagnose examples/emps_nominal.ssd examples/data/emps_train.csv \
    examples/data/emps_test_pulses.csv --out "$dir/emps-both" >/dev/null 2>&1
}
# each build writes into the same folder, so that paths inside the files
# (the rerun command of report.json) are the same
for side in old new; do
  bin=$old; [ $side = new ] && bin=$new
  outputs "$bin" "$out/run"
  if [ $suite = 1 ]; then
    .venv/bin/python tests/independent/suite.py --seeds 3 --fricsim "$bin" \
      --out "$out/run/suite" >/dev/null 2>&1
  fi
  rm -rf "$out/$side"; mv "$out/run" "$out/$side"
done
# report.json and the result files; the suite's own table holds timings
# report.json is compared without its timings (keys ending in _seconds)
same() {
  case "$1" in
    *report.json) python3 - "$1" "$2" <<'PY'
import json, sys
def strip(v):
    if isinstance(v, dict):
        return {k: strip(x) for k, x in v.items() if not k.endswith("_seconds")}
    if isinstance(v, list):
        return [strip(x) for x in v]
    return v
a, b = (strip(json.load(open(p))) for p in sys.argv[1:])
sys.exit(a != b)
PY
    ;;
    *) cmp -s "$1" "$2" ;;
  esac
}
differ=$(cd "$out/old" && find . -type f \( -name '*.csv' -o -name '*.mat' -o -name 'report.json' -o -name 'refitted.ssp' \) \
  -not -path './suite/suite.*' | sort | while read -r f; do
    same "$f" "../new/$f" || echo "$f"
  done)
count=$(cd "$out/old" && find . -type f \( -name '*.csv' -o -name '*.mat' -o -name 'report.json' -o -name 'refitted.ssp' \) -not -path './suite/suite.*' | wc -l)
if [ -n "$differ" ]; then
  echo "differ:"; echo "$differ"; exit 1
fi
echo "$count files compared, all the same byte for byte (report.json: but its timings) ($out)"
