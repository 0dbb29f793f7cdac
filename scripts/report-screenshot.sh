#!/usr/bin/env bash
# The README's picture of a diagnosis report: `fricsim diagnose` on the
# EMPS benchmark, its report.html rendered by headless Chromium, the first
# 1200 x 1800 pixels written to docs/images/report.png.
#
#   scripts/report-screenshot.sh        (after ./build-fmu.sh)
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/setup-browser.sh
out=out/report-screenshot
target/release/fricsim diagnose examples/emps_nominal.ssd examples/data/emps_train.csv \
    --heldout examples/data/emps_test_pulses.csv --out "$out/emps" > /dev/null
mkdir -p docs/images
chromium --headless --no-sandbox --disable-gpu --disable-quic --no-first-run \
    --disable-background-networking --disable-component-update --disable-sync \
    --hide-scrollbars --user-data-dir="$out/chromium-profile" \
    --window-size=1200,1800 --screenshot="$PWD/docs/images/report.png" \
    "file://$PWD/$out/emps/report.html" 2> "$out/chromium.log"
echo "wrote docs/images/report.png"
