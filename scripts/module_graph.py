#!/usr/bin/env python3
"""Prints the module dependency graph of Atlas as Graphviz DOT, read from the CMake link lines
(libatlas/CMakeLists.txt's atlas_module(...) calls, nodes/, apps/, python/), so the picture in
docs/architecture.md is the build's own contract, not a drawing.

    /usr/bin/python3 scripts/module_graph.py | dot -Tsvg -o docs/images/architecture.svg

Only edges between Atlas targets are drawn; each box lists the module's main third-party
libraries. Edges implied by another path (a -> b -> c makes a -> c redundant) are dropped so
the layering reads top to bottom.
"""
import re
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent

# What each module holds (one line under its name); keep in step with docs/architecture.md.
ROLE = {
    "core": "fields, values, hashing, errors,\\nmemory budget, parallel-for (fixed blocks)",
    "noise": "tileable noise kernels, value FBM",
    "compress": "BC1/BC4/BC6H codecs, DDS container\\n(in memory)",
    "io": "file formats: EXR, PNG/TGA, VDB, DDS files,\\nTGA stacks, Nubis pack, meshes and points,\\nYAML documents, the output-format table",
    "graph": "declarations, graph files,\\nevaluator, caches",
    "volume": "voxel authoring, SDF, mesh repair",
    "ndf": "2D NDFs, presets, forecasts",
    "sim": "cloud-growth solver",
    "render": "preview ray-marcher",
    "nodes": "one file per node type",
    "capi": "C API (atlas/atlas.h)",
    "atlas": "the CLI",
    "python": "Python bindings",
}
THIRD_PARTY = {
    "TBB::tbb": "TBB", "yaml-cpp": "yaml-cpp", "OpenEXR::OpenEXR": "OpenEXR", "OpenImageIO::OpenImageIO": "OIIO",
    "OpenVDB::openvdb": "OpenVDB", "CGAL::CGAL": "CGAL", "${TETGEN_LIBRARY}": "TetGen", "nlohmann_json::nlohmann_json": "json",
}


def target_name(token):
    token = token.strip()
    for prefix in ("atlas::", "atlas_"):
        if token.startswith(prefix):
            return token[len(prefix):]
    return None


def read_graph():
    deps, libs = {}, {}
    text = (ROOT / "libatlas/CMakeLists.txt").read_text()
    for m in re.finditer(r"^atlas_module\((\w+)([^)]*)\)", text, re.M):
        name, args = m.group(1), m.group(2).split()
        deps[name] = {t for t in (target_name(a) for a in args) if t and t != name}
        libs[name] = [THIRD_PARTY[a] for a in args if a in THIRD_PARTY]
    lines = {
        "nodes": ("nodes/CMakeLists.txt", r"target_link_libraries\(atlas_nodes([^)]*)\)"),
        "atlas": ("apps/CMakeLists.txt", r"target_link_libraries\(atlas\s([^)]*)\)"),
        "python": ("python/CMakeLists.txt", r"target_link_libraries\(atlas_python([^)]*)\)"),
    }
    for name, (path, pattern) in lines.items():
        f = ROOT / path
        if not f.exists():
            continue
        m = re.search(pattern, f.read_text())
        if not m:
            continue
        deps[name] = {t for t in (target_name(a) for a in m.group(1).split()) if t and t not in ("warnings", name)}
        libs.setdefault(name, [])
    for name in deps:
        deps[name] = {d for d in deps[name] if d in deps}
    return deps, libs


def reachable(deps, start, skip_edge):
    seen, todo = set(), [d for d in deps[start] if (start, d) != skip_edge]
    while todo:
        n = todo.pop()
        if n in seen:
            continue
        seen.add(n)
        todo.extend(deps.get(n, ()))
    return seen


def main():
    deps, libs = read_graph()
    out = ["digraph atlas {", '  rankdir=TB; nodesep=0.25; ranksep=0.45;',
           '  node [shape=box, style="rounded,filled", fillcolor="#f4f6fb", fontname="Helvetica", fontsize=11];',
           '  edge [color="#5a6a8a", arrowsize=0.7];']
    front = {"atlas", "python", "capi", "nodes"}
    for name in sorted(deps):
        label = f"<b>{name}</b>"
        role = ROLE.get(name, "")
        extra = ", ".join(libs.get(name, []))
        text = role + (("\\n[" + extra + "]") if extra else "")
        colour = "#fdf1e3" if name in front else ("#e8f3e8" if name in ("core", "io") else "#f4f6fb")
        out.append(f'  "{name}" [label="{name}\\n{text}", fillcolor="{colour}"];')
    for a in sorted(deps):
        for b in sorted(deps[a]):
            if b in reachable(deps, a, (a, b)):
                continue  # implied by a longer path
            out.append(f'  "{a}" -> "{b}";')
    out.append("}")
    sys.stdout.write("\n".join(out) + "\n")


if __name__ == "__main__":
    main()
