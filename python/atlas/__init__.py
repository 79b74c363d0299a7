"""Atlas from Python: load a node graph, set parameters, cook, read fields as NumPy arrays.

    import atlas
    s = atlas.Session()
    s.load("examples/quickstart.yaml")
    s.set("coverage", "in_min", 0.5)
    report = s.cook(jobs=4, progress=lambda f, task, done, total: print(f"{f:.0%} {task}"))
    density = s.get("coverage")["density"]      # read-only (nz, ny, nx) float32 view, no copy

Errors are atlas.Error (atlas.ParseError carries .file, .line, .column). See docs/embedding.md.
"""
from ._atlas import (  # noqa: F401
    CancelledError,
    CookContext,
    Error,
    Field2D,
    Field3D,
    MemoryBudgetError,
    NodeRegistry,
    ParseError,
    Session,
    __version__,
    builtin_nodes,
    node_types,
)

__all__ = [
    "CancelledError", "CookContext", "Error", "Field2D", "Field3D", "MemoryBudgetError",
    "NodeRegistry", "ParseError", "Session", "builtin_nodes", "node_types", "__version__",
]
