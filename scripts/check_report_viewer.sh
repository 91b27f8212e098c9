#!/usr/bin/env bash
# Opens a report.html of `sft reconstruct` in headless Chromium (software WebGL: SwiftShader),
# prints what its 3D view says about itself (#sft3d-status: "loaded; pixels drawn: result N of M,
# start N of M"), and writes a screenshot. Exits 0 when both views drew at least MIN_PIXELS pixels
# that differ from the background, 1 when not, 2 on usage errors or a missing Chromium.
#
#   scripts/check_report_viewer.sh REPORT.html SCREENSHOT.png [MIN_PIXELS]
#
# Chromium comes from `bash scripts/setup.sh --with-chromium`.
set -euo pipefail
if [[ $# -lt 2 ]]; then
  echo "usage: $0 REPORT.html SCREENSHOT.png [MIN_PIXELS]" >&2
  exit 2
fi
report="$(realpath "$1")"
shot="$(realpath -m "$2")"
min_pixels="${3:-500}"
chromium="$(command -v chromium || command -v chromium-browser || true)"
if [[ -z "$chromium" ]]; then
  echo "check_report_viewer: chromium not found (bash scripts/setup.sh --with-chromium)" >&2
  exit 2
fi
if [[ ! -f "$report" ]]; then
  echo "check_report_viewer: $1: file not found" >&2
  exit 2
fi
profile="$(mktemp -d)"
trap 'rm -rf "$profile"' EXIT
flags=(--headless --no-sandbox --disable-gpu-sandbox --use-gl=angle --use-angle=swiftshader
       --enable-unsafe-swiftshader --allow-file-access-from-files --user-data-dir="$profile"
       --virtual-time-budget=20000 --window-size=1100,2400 --hide-scrollbars)
dom="$("$chromium" "${flags[@]}" --dump-dom "file://$report" 2>/dev/null)"
"$chromium" "${flags[@]}" --screenshot="$shot" "file://$report" > /dev/null 2>&1 || true
status="$(printf '%s' "$dom" | sed -n 's/.*<span id="sft3d-status">\([^<]*\)<\/span>.*/\1/p' | head -n 1)"
echo "3D view: ${status:-no #sft3d-status in the page}"
echo "screenshot: $shot"
counts=($(printf '%s' "$status" | grep -o '[a-z]* [0-9]* of' | awk '{print $2}'))
if [[ "$status" != loaded* || ${#counts[@]} -eq 0 ]]; then exit 1; fi
for n in "${counts[@]}"; do
  if (( n < min_pixels )); then exit 1; fi
done
exit 0
