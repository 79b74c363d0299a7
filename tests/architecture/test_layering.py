"""Issue 13, item 4: the module layering the architecture page promises.

- Only atlas/core/parallel.h calls TBB: every other file uses its helpers, whose
  fixed blocks keep the bytes the same on any thread count.
- The algorithm modules (noise, compress, volume, ndf, sim, render) work on memory:
  no file streams, no std::filesystem, no core/files.h. Files are opened in io
  (and by the nodes and the CLI that compose io with the algorithms).
- Each module includes only the modules its CMake line links (libatlas/CMakeLists.txt).
- The Python binding files (python/src) call each other's functions without a circle.
"""
import os
import pathlib
import re

ROOT = pathlib.Path(os.environ.get("ATLAS_SOURCE_DIR", pathlib.Path(__file__).resolve().parents[2]))
LIB = ROOT / "libatlas"
ALGORITHM_MODULES = ["noise", "compress", "volume", "ndf", "sim", "render"]
CPP = (".cpp", ".h", ".hpp", ".cc")


def sources(*dirs):
    for d in dirs:
        for p in sorted((ROOT / d).rglob("*")):
            if p.suffix in CPP and p.is_file():
                yield p


def module_files(module):
    return list(sources(f"libatlas/src/{module}", f"libatlas/include/atlas/{module}"))


def code_lines(path):
    """Lines with // comments removed (a comment may name what it does not use)."""
    for n, line in enumerate(path.read_text(encoding="utf-8", errors="replace").splitlines(), 1):
        yield n, line.split("//", 1)[0]


def offences(paths, pattern):
    rx = re.compile(pattern)
    return [f"{os.path.relpath(p, ROOT)}:{n}: {line.strip()}" for p in paths for n, line in code_lines(p) if rx.search(line)]


def test_only_core_parallel_calls_tbb():
    allowed = LIB / "include/atlas/core/parallel.h"
    files = [p for p in sources("libatlas", "nodes", "apps", "python", "plugins") if p != allowed]
    assert len(files) > 100
    bad = offences(files, r"#\s*include\s*<tbb/|\btbb::")
    assert not bad, "TBB outside atlas/core/parallel.h:\n" + "\n".join(bad)


def test_algorithm_modules_open_no_files():
    pattern = r"#\s*include\s*<(fstream|filesystem)>|\bstd::(i|o)?fstream\b|\bstd::filesystem\b|\b(fopen|freopen|open)\s*\(|#\s*include\s*\"atlas/core/files\.h\""
    for module in ALGORITHM_MODULES:
        files = module_files(module)
        assert files, module
        bad = offences(files, pattern)
        assert not bad, f"{module} opens files (they belong in io):\n" + "\n".join(bad)


def test_the_checks_can_fail():
    # Negative control: the patterns do catch what they look for.
    fake = pathlib.Path("/tmp/atlas_layering_fake.cpp")
    fake.write_text('#include <fstream>\nvoid f() { tbb::parallel_for(0, 1, [](int) {}); }\n')
    try:
        assert len(offences([fake], r"#\s*include\s*<(fstream|filesystem)>")) == 1
        assert len(offences([fake], r"#\s*include\s*<tbb/|\btbb::")) == 1
    finally:
        fake.unlink()


def link_lines():
    deps = {}
    for line in (LIB / "CMakeLists.txt").read_text().splitlines():
        m = re.match(r"\s*atlas_module\((\w+)(.*)\)", line.split("#", 1)[0])
        if m:
            deps[m.group(1)] = set(re.findall(r"atlas::(\w+)", m.group(2)))
    return deps


def closure(deps, m, seen=None):
    seen = set() if seen is None else seen
    for d in deps.get(m, ()):
        if d not in seen:
            seen.add(d)
            closure(deps, d, seen)
    return seen


def test_includes_follow_the_link_lines():
    deps = link_lines()
    assert {"core", "io", "render", "volume"} <= set(deps)
    bad = []
    for module in deps:
        reach = closure(deps, module) | {module}
        for p in module_files(module):
            for n, line in code_lines(p):
                m = re.search(r'#\s*include\s*"atlas/(\w+)/', line)
                if m and m.group(1) in deps and m.group(1) not in reach:
                    bad.append(f"{p.relative_to(ROOT)}:{n}: {module} includes atlas/{m.group(1)} but does not link it")
    assert not bad, "\n".join(bad)


def python_binding_uses():
    """python/src: {file: files whose functions it calls}, for the functions its headers declare
    at namespace scope (a use is the name in a file's code; the definer is the .cpp that defines it)."""
    src = ROOT / "python/src"
    declared = set()
    for h in sorted(src.glob("*.h")):
        declared |= set(re.findall(r"^(?:[\w:<>]+[\s*&]+)+(\w+)\(", h.read_text(), re.M))
    cpps = sorted(src.glob("*.cpp"))
    definer = {}
    for p in cpps:
        for _, line in code_lines(p):
            m = re.match(r"^[^\s#].*?\b(\w+)\([^;]*$", line)
            if m and m.group(1) in declared:
                definer[m.group(1)] = p.name
    uses = {p.name: set() for p in cpps}
    for p in cpps:
        code = "\n".join(line for _, line in code_lines(p))
        for name, where in definer.items():
            if where != p.name and re.search(rf"\b{name}\b", code):
                uses[p.name].add(where)
    return uses, definer


def circle(uses):
    """A list of files that use each other in a circle, or None."""
    state = {}

    def visit(n, path):
        state[n] = "open"
        for d in sorted(uses.get(n, ())):
            if state.get(d) == "open":
                return path[path.index(d):] + [d] if d in path else [n, d]
            if d not in state:
                found = visit(d, path + [d])
                if found:
                    return found
        state[n] = "done"
        return None

    for n in sorted(uses):
        if n not in state:
            found = visit(n, [n])
            if found:
                return found
    return None


def test_python_binding_files_form_no_circle():
    # module.cpp binds the Python node types (python_nodes.cpp); what both use (errors,
    # parameters as Python data) lives in files of its own, so neither uses the other back.
    uses, definer = python_binding_uses()
    assert {"bind_python_nodes", "python_error_message", "param_from_python", "declaration_to_python"} <= set(definer)
    assert "python_nodes.cpp" in uses["module.cpp"]
    found = circle(uses)
    assert not found, "python/src files use each other in a circle: " + " -> ".join(found)
    assert circle({"a": {"b"}, "b": {"c"}, "c": {"a"}}) == ["a", "b", "c", "a"]  # the check can fail


def header_sources(header, text=None):
    """The sources a public header leads to: its namesake under libatlas/src, or the files its
    opening comment names ("Implemented in a.cpp, b.cpp (src/module/)"); "Header-only." is []."""
    text = header.read_text(encoding="utf-8") if text is None else text
    module = header.parent.name if header.parent.name != "atlas" else None
    namesakes = list((LIB / "src").rglob(header.stem + ".cpp"))
    if namesakes:
        return namesakes
    head = "\n".join(text.splitlines()[:60])
    if re.search(r"Header-only[.,]", head):
        return []
    m = re.search(r"Implemented in (.*?)(\n\s*(//|\*)?\s*\n|#pragma)", head, re.S)  # to the end of its paragraph
    if not m:
        return None
    found = []
    for name in re.findall(r"[\w/]+\.cpp", m.group(1)):
        hits = [p for p in (LIB / "src").rglob(pathlib.Path(name).name) if module is None or p.parent.name == module]
        if not hits:
            raise AssertionError(f"{os.path.relpath(header, ROOT)} names {name}, which does not exist")
        found += hits
    return found or None


def test_every_public_header_leads_to_its_source():
    # Issue 47 item 4: a newcomer opening a header finds its code by the name.
    headers = sorted((LIB / "include/atlas").rglob("*.h"))
    assert len(headers) > 80
    lost = [os.path.relpath(h, ROOT) for h in headers if header_sources(h) is None]
    assert not lost, "public headers with no source of their name and no 'Implemented in ...' / 'Header-only.' note:\n" + "\n".join(lost)
    # Negative control: a header that says nothing is caught, and a named file must exist.
    fake = LIB / "include/atlas/core/zz_fake.h"
    assert header_sources(fake, "// atlas/core/zz_fake.h - nothing.\n#pragma once\n") is None
    try:
        header_sources(fake, "// atlas/core/zz_fake.h - x.\n// Implemented in no_such_file.cpp.\n#pragma once\n")
        raise RuntimeError("a missing source was accepted")
    except AssertionError:
        pass
