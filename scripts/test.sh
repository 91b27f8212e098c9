#!/usr/bin/env bash
# Installs everything, builds, and runs the default test suite (ctest, excluding label "long").
# Pass --all to include long tests.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh
bash scripts/build.sh
label_args=(-LE long)
if [[ "${1:-}" == "--all" ]]; then label_args=(); fi
cd build
ctest --output-on-failure -j "$(nproc)" "${label_args[@]}"
