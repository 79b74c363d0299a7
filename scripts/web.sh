#!/usr/bin/env bash
# Builds the page `atlas view` writes (plugins/web, docs/web.md): three.js,
# @takram/three-clouds and its peers from the npm registry at the versions
# package-lock.json pins, bundled by esbuild into plugins/web/dist. Nothing of
# theirs is committed. scripts/test.sh runs it; the demo does not need it.
set -euo pipefail
cd "$(dirname "$0")/../plugins/web"
if ! command -v node >/dev/null || ! command -v npm >/dev/null; then
  echo "web: needs Node.js and npm (scripts/setup.sh installs them)" >&2
  exit 1
fi
if [ ! -f node_modules/.package-lock.json ] || [ package-lock.json -nt node_modules/.package-lock.json ]; then
  echo "web: installing the page's npm packages" >&2
  npm ci --no-audit --no-fund --ignore-scripts >&2
fi
node build.mjs >&2
