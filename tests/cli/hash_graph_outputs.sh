#!/usr/bin/env bash
# Cooks every graph in graphs/ and examples/ with the given atlas binary (no cache,
# one thread) and prints "sha256  GRAPH/FILE" for every file it writes, so two
# binaries can be shown to write identical outputs:
#   tests/cli/hash_graph_outputs.sh OLD/atlas > old.txt
#   tests/cli/hash_graph_outputs.sh NEW/atlas > new.txt && diff old.txt new.txt
# A graph that fails or runs past ATLAS_HASH_TIMEOUT seconds (default 900) prints
# "FAILED GRAPH (status)" instead.
set -uo pipefail
atlas="$1"
cd "$(dirname "$0")/../.."
timeout_s="${ATLAS_HASH_TIMEOUT:-900}"
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT
for g in $(find graphs examples -name '*.yaml' | sort); do
  out="$work/$(echo "$g" | tr / _)"
  mkdir -p "$out"
  if timeout "$timeout_s" "$atlas" cook "$g" --out "$out" --no-cache --quiet --jobs 1 >/dev/null 2>"$out.err"; then
    (cd "$out" && find . -type f | sort | xargs -r sha256sum | sed "s|  \./|  $g/|")
  else
    echo "FAILED $g ($?): $(head -c 300 "$out.err" | tr '\n' ' ')"
  fi
  rm -rf "$out"
done
