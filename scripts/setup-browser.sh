#!/usr/bin/env bash
# Install Chromium from the distribution's packages when it is missing: the
# tests render `fricsim diagnose`'s report.html in it (headless) and
# scripts/report-screenshot.sh takes the README's picture with it.
# Idempotent; needs root or sudo for apt-get on a fresh machine.
set -euo pipefail
if command -v chromium > /dev/null 2>&1; then
    exit 0
fi
sudo=""
if [ "$(id -u)" -ne 0 ]; then
    sudo="sudo"
fi
echo "setup-browser.sh: installing chromium (Debian package) for the report tests" >&2
$sudo env DEBIAN_FRONTEND=noninteractive apt-get install -o DPkg::Lock::Timeout=600 -y -q chromium > /dev/null \
    || { $sudo apt-get update -o DPkg::Lock::Timeout=600 -q > /dev/null && $sudo env DEBIAN_FRONTEND=noninteractive apt-get install -o DPkg::Lock::Timeout=600 -y -q chromium > /dev/null; }
command -v chromium > /dev/null
