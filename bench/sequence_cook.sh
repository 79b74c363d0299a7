#!/usr/bin/env bash
# Sequences (issue 43 item 6): a 60-frame superstorm lifecycle and a 24-slot forecast
# day, each cooked as one `atlas cook --frames` run against a cold cook of one of its
# frames in a new process. Prints wall and CPU per frame, the incremental cost of a
# frame against the cold cook, and the sequence's size on disk, as docs/PERFORMANCE.md
# records them. Not a test. Time it only when nothing else runs.
# Usage: bench/sequence_cook.sh [BUILD_DIR] [JOBS]
#   the lifecycle: graphs/superstorm_lifecycle.yaml at a frame every 8 s (fps 0.125), frames 0:59
#   the forecast day: graphs/fc6_forecast.yaml with `time: {start: 0, end: 23, fps: 1}` and the
#     forecast node's start_hour keyed to the time (one 1-hour slot per frame; slices: 1)
set -euo pipefail
cd "$(dirname "$0")/.."
BUILD="$(cd "${1:-build}" && pwd)"
JOBS="${2:-2}"
ATLAS="$BUILD/bin/atlas"
WORK="$(mktemp -d /tmp/atlas_sequence_XXXXXX)"
trap 'rm -rf "$WORK"' EXIT
REPO="$(pwd)"

python3 - "$REPO" "$WORK" <<'EOF'
import sys
repo, work = sys.argv[1], sys.argv[2]
s = open(f"{repo}/graphs/superstorm_lifecycle.yaml").read()
assert "fps: 0.05}" in s
open(f"{work}/lifecycle60.yaml", "w").write(s.replace("fps: 0.05}", "fps: 0.125}"))
s = open(f"{repo}/graphs/fc6_forecast.yaml").read()
s = s.replace("nodes:\n", "time: {start: 0, end: 23, fps: 1}   # graph seconds = forecast hours\n\nnodes:\n", 1)
old = "start_hour: 0, step_hours: 3, slices: 40,"
assert old in s
s = s.replace(old, "start_hour: {keys: [[0, 0], [23, 23]], interp: linear}, step_hours: 1, slices: 1,")
s = s.replace("fc6/", f"{repo}/graphs/fc6/")
open(f"{work}/forecast_day.yaml", "w").write(s)
EOF

# run LABEL ARGS...: one process; prints "wall cpu" (seconds) into $WORK/last
run() {
  /usr/bin/time -f "%e %U %S %M" -o "$WORK/time" "$ATLAS" cook "$@" --no-cache --quiet --jobs "$JOBS" >/dev/null
  read -r wall user sys rss <"$WORK/time"
  echo "$wall $(echo "$user + $sys" | bc) $rss" >"$WORK/last"
}

sequence() {
  local name="$1" frames="$2" cold_frame="$3"
  local g="$WORK/$name.yaml"
  local colds=()
  for i in 1 2 3; do
    rm -rf "$WORK/cold"
    run "$g" --frames "$cold_frame" --out "$WORK/cold"
    colds+=("$(cat "$WORK/last")")
  done
  rm -rf "$WORK/seq"
  local load; load="$(cut -d' ' -f1-3 /proc/loadavg)"
  run "$g" --frames "$frames" --out "$WORK/seq" --report "$WORK/report.json"
  local seq; seq="$(cat "$WORK/last")"
  python3 - "$name" "$WORK" "$seq" "$load" "${colds[@]}" <<'EOF'
import json, os, statistics, sys
name, work, seq, load, colds = sys.argv[1], sys.argv[2], sys.argv[3], sys.argv[4], sys.argv[5:]
cw = statistics.median(float(c.split()[0]) for c in colds)
cc = statistics.median(float(c.split()[1]) for c in colds)
sw, sc, rss = (float(x) for x in seq.split())
rep = json.load(open(f"{work}/report.json"))["graphs"]
n = len(rep)
inproc = [g["seconds"] for g in rep]
man = json.load(open(f"{work}/seq/frames.json"))
changed = [sum(o["changed"] for o in f["outputs"]) for f in man["frames"][1:]]
size = files = 0
for root, _, fs in os.walk(f"{work}/seq"):
    for f in fs:
        if f == ".atlas-outputs.json":
            continue
        size += os.path.getsize(os.path.join(root, f))
        files += 1
# A frame after the first: what the sequence run cost beyond its first (cold) frame.
fw, fc = (sw - cw) / (n - 1), (sc - cc) / (n - 1)
print(f"{name}: {n} frames, load {load}")
print(f"  cold cook of one frame (new process, median of 3): {cw:.3f} s wall, {cc:.3f} s CPU")
print(f"  sequence: {sw:.2f} s wall, {sc:.2f} s CPU, {rss/1024:.0f} MB peak RSS")
print(f"  per frame after the first: {fw*1000:.1f} ms wall ({fw/cw*100:.1f}% of the cold cook), "
      f"{fc*1000:.1f} ms CPU ({fc/cc*100:.1f}%); in-process cook median {statistics.median(inproc[1:])*1000:.1f} ms "
      f"(the first frame {inproc[0]*1000:.1f} ms)")
print(f"  outputs changed per frame: {min(changed)}-{max(changed)} of {len(man['frames'][0]['outputs'])}")
print(f"  on disk: {size/1e6:.1f} MB in {files} files ({size/n/1e6:.2f} MB per frame, frames.json included)")
EOF
}

sequence lifecycle60 0:59 30
sequence forecast_day all 12
