#!/usr/bin/env bash
# Main job: build the FMUs, then co-simulate a seed scenario and write a
# result CSV and a PNG plot into out/.
set -euo pipefail
cd "$(dirname "$0")"
./build-fmu.sh
echo "run-main.sh: co-simulation host not built yet" >&2
exit 1
