#!/usr/bin/env bash
# The hidden-effect suite of `fricsim diagnose` and, on the same cases, the
# PySINDy sparse-regression baseline; rewrites the part of BENCHMARKS.md
# between the hidden-effect-suite markers.
#
#   scripts/hidden-effect-suite.sh [--seeds N] [--null-seeds N] [--quick] [--no-update]
#
# Default: every effect at 10 % and 5 % with 3 noise seeds, the pair
# direction_dependent+viscous with 3 seeds, 20 cases with nothing hidden
# (about half an hour here). --quick: 10 % only, 1 seed, 2 null cases, and
# BENCHMARKS.md is left alone unless --update is given.
# Outputs (tables and JSON) in out/hidden-effect-suite/.
set -euo pipefail
cd "$(dirname "$0")/.."
seeds=3
null_seeds=20
magnitudes=(--magnitude 0.1 --magnitude 0.05)
update=1
while [ $# -gt 0 ]; do
    case "$1" in
        --seeds) seeds=$2; shift 2 ;;
        --null-seeds) null_seeds=$2; shift 2 ;;
        --quick) seeds=1; null_seeds=2; magnitudes=(--magnitude 0.1); update=0; shift ;;
        --update) update=1; shift ;;
        --no-update) update=0; shift ;;
        -h|--help) sed -n 2,13p "$0"; exit 0 ;;
        *) echo "hidden-effect-suite.sh: unknown option $1 (see --help)" >&2; exit 2 ;;
    esac
done
out=out/hidden-effect-suite
rm -rf "$out"
mkdir -p "$out"

./build-fmu.sh > /dev/null
cargo build --release --quiet -p fricsim-bench --bin hidden-effect-suite
suite=target/release/hidden-effect-suite
grid=(--all "${magnitudes[@]}" --seeds "$seeds" --null-seeds "$null_seeds")

# the baseline's own venv (pinned PySINDy), rebuilt when the pins change
stamp=.venv-baseline/.requirements.sha256
want=$(sha256sum scripts/requirements-baseline.txt | cut -d' ' -f1)
if ! { [ -x .venv-baseline/bin/python ] && [ -f "$stamp" ] && [ "$(cat "$stamp")" = "$want" ]; }; then
    "${PYTHON:-python3}" -m venv .venv-baseline
    .venv-baseline/bin/pip install --quiet --disable-pip-version-check -r scripts/requirements-baseline.txt
    echo "$want" > "$stamp"
fi

"$suite" "${grid[@]}" --json "$out/diagnose.json" | tee "$out/diagnose.md"
"$suite" "${grid[@]}" --export "$out/export" 2> /dev/null
.venv-baseline/bin/python scripts/sindy-baseline.py "$out/export" --json "$out/sindy.json" | tee "$out/sindy.md"

args=(--diagnose "$out/diagnose.json" --sindy "$out/sindy.json"
      --command "scripts/hidden-effect-suite.sh $*")
if [ "$update" = 1 ]; then
    python3 scripts/suite-report.py "${args[@]}" --update BENCHMARKS.md
    echo "updated BENCHMARKS.md"
else
    python3 scripts/suite-report.py "${args[@]}"
fi
