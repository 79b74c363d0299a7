#!/usr/bin/env python3
"""Runs the documented commands: every fenced block marked runnable in README.md and docs/*.md.

A block is runnable when the line before its fence is `<!-- runnable -->` (invisible in the
rendered page). ```sh blocks run in bash (set -euo pipefail), ```python blocks in the system
Python with the atlas module on PYTHONPATH. The blocks of one document run in order, in a scratch
copy of the repository's graphs/, examples/ and docs/ (so nothing is written into the source tree),
with `build` pointing at the build under test and `atlas` on PATH. A failing block fails the test
with the document, its line and what the command printed.

    run_doc_commands.py --source SRC --build BUILD [--only docs/tutorial.md] [--list] [--keep DIR]

--keep DIR runs in DIR (kept afterwards) instead of a scratch folder: scripts/make_tutorial_images.sh
takes the tutorial's pictures from there.
"""
import argparse
import os
import pathlib
import re
import shutil
import subprocess
import sys
import tempfile
import time

MARK = "<!-- runnable -->"
FENCE = re.compile(r"^```(sh|bash|python)\s*$")


def blocks(path):
    """(line, language, text) of each runnable block of a Markdown file."""
    lines = path.read_text().splitlines()
    out = []
    i = 0
    while i < len(lines):
        if lines[i].strip() == MARK:
            m = FENCE.match(lines[i + 1]) if i + 1 < len(lines) else None
            if not m:
                raise SystemExit(f"{path}:{i + 1}: '{MARK}' must be followed by a ```sh, ```bash or ```python fence")
            j = i + 2
            while j < len(lines) and lines[j].strip() != "```":
                j += 1
            if j == len(lines):
                raise SystemExit(f"{path}:{i + 2}: the runnable block is not closed")
            out.append((i + 3, m.group(1), "\n".join(lines[i + 2:j]) + "\n"))
            i = j
        i += 1
    return out


def documents(source):
    return [source / "README.md"] + sorted((source / "docs").glob("*.md"))


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--source", type=pathlib.Path, required=True)
    ap.add_argument("--build", type=pathlib.Path, required=True)
    ap.add_argument("--only", action="append", default=[], help="a document (relative to SOURCE) to run alone")
    ap.add_argument("--list", action="store_true", help="print the runnable blocks and stop")
    ap.add_argument("--python", default="/usr/bin/python3")
    ap.add_argument("--keep", type=pathlib.Path, help="run in this folder and keep it (one document)")
    a = ap.parse_args()
    source = a.source.resolve()
    docs = [source / o for o in a.only] if a.only else documents(source)
    found = [(d, b) for d in docs for b in blocks(d)]
    if a.list:
        for d, (line, lang, text) in found:
            print(f"{d.relative_to(source)}:{line} ({lang})\n{text}")
        return 0
    if not found:
        print("no runnable blocks found", file=sys.stderr)
        return 1

    failures = 0
    for doc in docs:
        doc_blocks = [b for d, b in found if d == doc]
        if not doc_blocks:
            continue
        rel = doc.relative_to(source)
        with tempfile.TemporaryDirectory(prefix="atlas_doc_") as tmp:
            work = pathlib.Path(tmp)
            if a.keep:
                shutil.rmtree(a.keep, ignore_errors=True)
                work = a.keep.resolve()
                work.mkdir(parents=True)
            for part in ("graphs", "examples", "docs", "scripts"):
                shutil.copytree(source / part, work / part, ignore=shutil.ignore_patterns("cumulus_out", "images"))
            shutil.copy(source / "README.md", work / "README.md")
            (work / "build").symlink_to(a.build.resolve())
            env = dict(os.environ)
            env["PATH"] = f"{a.build.resolve() / 'bin'}:{env['PATH']}"
            env["PYTHONPATH"] = str(a.build.resolve() / "python")
            for line, lang, text in doc_blocks:
                cmd = ["bash", "-euo", "pipefail", "-c", text] if lang in ("sh", "bash") else [a.python, "-c", text]
                block_env = dict(env)
                # A sanitized build's Python module needs the ASan runtime loaded first (tests/CMakeLists.txt).
                if lang == "python" and os.environ.get("ATLAS_PYTHON_PRELOAD"):
                    block_env["LD_PRELOAD"] = os.environ["ATLAS_PYTHON_PRELOAD"]
                    block_env["ASAN_OPTIONS"] = "detect_leaks=0:abort_on_error=1"
                t0 = time.time()
                r = subprocess.run(cmd, cwd=work, env=block_env, capture_output=True, text=True)
                took = time.time() - t0
                if r.returncode != 0:
                    failures += 1
                    print(f"FAILED {rel}:{line} ({lang}, exit {r.returncode}, {took:.1f} s)\n--- block\n{text}"
                          f"--- stdout (tail)\n{r.stdout[-2000:]}\n--- stderr (tail)\n{r.stderr[-3000:]}", file=sys.stderr)
                    break  # later blocks of the document build on this one
                print(f"ok {rel}:{line} ({lang}, {took:.1f} s)")
    print(f"{len(found)} runnable blocks in {len(docs)} documents: {failures} failed")
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
