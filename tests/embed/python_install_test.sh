#!/usr/bin/env bash
# The Python front ends as a user installs them (issue 45): `cmake --install` puts atlas and
# atlas_dask in one folder that Debian's python3 searches under the default prefix, atlas-dask runs
# from the build tree and from the install, and a wheel built from the tree installs into a fresh
# virtual environment and cooks.
#   python_install_test.sh BUILD_DIR SOURCE_DIR WORK_DIR
set -euo pipefail
build="$(cd "$1" && pwd)" src="$(cd "$2" && pwd)" work="$3"
py=/usr/bin/python3
rm -rf "$work" && mkdir -p "$work"
# The sanitized build's module needs the ASan runtime first; only the Python processes get it.
pyenv=()
[ -n "${ATLAS_PYTHON_PRELOAD:-}" ] && pyenv=(env "LD_PRELOAD=$ATLAS_PYTHON_PRELOAD" "ASAN_OPTIONS=detect_leaks=0:abort_on_error=1")

dir="$(sed -n 's/^ATLAS_PYTHON_INSTALL_DIR:STRING=//p' "$build/CMakeCache.txt")"
[ -n "$dir" ] || { echo "FAIL: no ATLAS_PYTHON_INSTALL_DIR in $build/CMakeCache.txt"; exit 1; }
# Debian's python3 searches <default prefix>/<dir>: nothing to set after `cmake --install build`.
"$py" -c "import sys; p='/usr/local/$dir'; assert p in sys.path, (p, sys.path)"

# A prefix Python does not search: the install says which variable to set.
cmake --install "$build" --prefix "$work/prefix" --component python > "$work/install.log"
grep -q "does not search $work/prefix/$dir; to import atlas and atlas_dask set PYTHONPATH=$work/prefix/$dir" "$work/install.log" || {
  echo "FAIL: the install did not say how to reach $work/prefix/$dir"; cat "$work/install.log"; exit 1; }
test -x "$work/prefix/bin/atlas-dask" || { echo "FAIL: atlas-dask is not an executable in $work/prefix/bin"; exit 1; }
test -f "$work/prefix/$dir/atlas_dask/__init__.py" && test -f "$work/prefix/$dir/atlas/__init__.py" || {
  echo "FAIL: atlas and atlas_dask are not both in $work/prefix/$dir"; find "$work/prefix" -name "__init__.py"; exit 1; }
"${pyenv[@]}" env PYTHONPATH="$work/prefix/$dir" "$py" -c "import atlas, atlas_dask; assert atlas.Session"
"$work/prefix/bin/atlas-dask" --help | grep -q "usage: atlas-dask"
# The build tree's copy (it failed with ModuleNotFoundError: atlas_dask).
"$build/python/atlas_dask/atlas-dask" --help | grep -q "usage: atlas-dask"

# A wheel from the tree, with Debian's pip, setuptools and wheel (no index is reachable): the module
# comes from this build (ATLAS_BUILD_DIR), packed with atlas_dask and the atlas-dask entry point.
# The wheel's sources in a scratch copy: the test writes nothing into the source tree.
mkdir -p "$work/src/python"
cp "$src/pyproject.toml" "$src/setup.py" "$src/CMakeLists.txt" "$work/src/"
cp -r "$src/python/atlas" "$src/python/atlas_dask" "$work/src/python/"
# The build is used as it is (ctest built it; a second ninja in the same folder would race other tests).
(cd "$work/src" && ATLAS_BUILD_DIR="$build" ATLAS_WHEEL_NO_BUILD=1 "$py" -m pip wheel --no-build-isolation --no-deps --no-index -q -w "$work/dist" .)
wheel="$(ls "$work"/dist/atlas_clouds-*.whl)"
case "$wheel" in *-cp3*-linux_x86_64.whl) ;; *) echo "FAIL: not a platform wheel: $wheel"; exit 1 ;; esac
# A fresh environment; NumPy (the one run-time dependency) from Debian's site packages.
"$py" -m venv --system-site-packages "$work/venv"
"$work/venv/bin/pip" install -q --no-index --no-deps "$wheel"
cd "$work"
"${pyenv[@]}" "$work/venv/bin/python" - "$src/examples/quickstart.yaml" <<'PY'
import sys, atlas
assert "/venv/" in atlas.__file__, atlas.__file__
s = atlas.Session()
s.load(sys.argv[1])
d = s.get("coverage")["density"]
assert d.shape == (32, 128, 128) and 0 <= d.min() and d.max() <= 1, (d.shape, d.min(), d.max())
print("wheel ok:", atlas.__version__, atlas.__file__)
PY
"$work/venv/bin/atlas-dask" --help | grep -q "usage: atlas-dask"
echo "python install ok: $dir, $(basename "$wheel")"
