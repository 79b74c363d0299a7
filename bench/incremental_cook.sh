#!/usr/bin/env bash
# Incremental cooks of a graph (issue 17): CPU of a cold cook, a no-op cook and
# one late-parameter edit, each in a new process, as docs/PERFORMANCE.md
# records them. Not a test: it prints the figures and the load average.
# Usage: bench/incremental_cook.sh [BUILD_DIR] [GRAPH] [NODE.PARAM=VALUE]
set -euo pipefail
BUILD="${1:-build}"
GRAPH="${2:-graphs/cloudscape.yaml}"
EDIT="${3:-top_view.extinction}"
WORK="$(mktemp -d /tmp/atlas_incremental_XXXXXX)"
trap 'rm -rf "$WORK"' EXIT
cook() {
  local label="$1"; shift
  local load; load="$(cut -d' ' -f1-3 /proc/loadavg)"
  /usr/bin/time -f "%U %S %e" -o "$WORK/time" "$BUILD/bin/atlas" cook "$GRAPH" --out "$WORK/out" --cache "$WORK/cache" \
    --jobs 2 --quiet "$@" >"$WORK/stdout"
  read -r user sys wall <"$WORK/time"
  cpu="$(echo "$user + $sys" | bc)"
  echo "$label: cpu ${cpu} s (user $user, sys $sys), wall $wall s, load $load; $(head -1 "$WORK/stdout")"
  echo "$cpu"  >"$WORK/last_cpu"
}
cook cold; cold="$(cat "$WORK/last_cpu")"
cook no-op; noop="$(cat "$WORK/last_cpu")"
case "$EDIT" in *=*) cook late-edit --set "$EDIT" ;; *) cook late-edit --set "$EDIT=0.02" ;; esac
late="$(cat "$WORK/last_cpu")"
echo "no-op / cold = $(echo "scale=4; $noop / $cold" | bc), late edit / cold = $(echo "scale=4; $late / $cold" | bc)"
