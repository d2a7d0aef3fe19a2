"""The package's shape, read from its source with `ast` (nothing is imported): layers, and the
wings of `drake_dock.docking`, import only downwards; no import circles; no private name imported
across modules; no module over 500 lines, no class over 300 lines; module names unique, and none
an inflection of another; a wing's package only a docstring; tests/core reaches no Drake module
through any chain of imports; the compiled code sorts by np.argsort only."""
import ast
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
PACKAGE = ROOT / "drake_dock"

# A module may import its own layer or any layer below it (errors and the version at the bottom).
LAYERS = {"errors": 0, "__init__": 0, "core": 1, "systems": 2, "docking": 3, "studies": 4,
          "campaign": 5, "run": 6, "cli": 7, "__main__": 8}
# The wings of `drake_dock.docking` in their order (its docstring): a wing imports its own and
# the wings before it.
WINGS = {"scenario": 1, "geometry": 2, "checks": 3, "model": 4, "placement": 5, "report": 6}


def _module_name(path: Path) -> str:
    parts = list(path.relative_to(ROOT).with_suffix("").parts)
    if parts[-1] == "__init__":
        parts = parts[:-1]
    return ".".join(parts)


def _modules():
    return {_module_name(p): p for p in sorted(PACKAGE.rglob("*.py"))}


def _imports(path: Path, package: str):
    """(imported module, [names]) for every import in the file, relative imports resolved."""
    tree = ast.parse(path.read_text(), filename=str(path))
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            for a in node.names:
                yield a.name, []
        elif isinstance(node, ast.ImportFrom):
            if node.level:
                base = package.split(".")[:len(package.split(".")) - node.level + 1]
                mod = ".".join(base + ([node.module] if node.module else []))
            else:
                mod = node.module
            yield mod, [a.name for a in node.names]


def _layer(module: str) -> tuple[int, int]:
    """(layer, wing): the wing is 0 outside `drake_dock.docking` and for its package face."""
    parts = module.split(".")
    key = parts[1] if len(parts) > 1 else "__init__"
    wing = WINGS[parts[2]] if key == "docking" and len(parts) > 2 else 0
    return LAYERS[key], wing


def _internal_edges():
    mods = _modules()
    edges = {}
    for name, path in mods.items():
        package = name if path.name == "__init__.py" else name.rsplit(".", 1)[0]
        targets = set()
        for mod, names in _imports(path, package):
            for cand in [f"{mod}.{n}" for n in names] + [mod]:
                if cand in mods and cand != name:
                    targets.add(cand)
                    break
        edges[name] = targets
    return edges


def test_every_module_has_a_layer():
    for name in _modules():
        _layer(name)


def test_imports_only_go_down():
    bad = [(a, b) for a, bs in _internal_edges().items() for b in bs if _layer(b) > _layer(a)]
    assert not bad, f"imports going up a layer: {bad}"


def test_no_import_circles():
    edges = _internal_edges()
    state = {}

    def visit(node, stack):
        state[node] = 1
        for nxt in edges[node]:
            if state.get(nxt) == 1:
                raise AssertionError("import circle: " + " -> ".join(stack + [node, nxt]))
            if nxt not in state:
                visit(nxt, stack + [node])
        state[node] = 2

    for node in edges:
        if node not in state:
            visit(node, [])


def test_no_private_name_imported_across_modules():
    mods = _modules()
    bad = []
    for name, path in mods.items():
        package = name if path.name == "__init__.py" else name.rsplit(".", 1)[0]
        for mod, names in _imports(path, package):
            if mod and mod.startswith("drake_dock"):
                bad += [(name, mod, n) for n in names if n.startswith("_") and n != "__version__"]
    assert not bad, bad


def test_module_and_class_sizes():
    for name, path in _modules().items():
        text = path.read_text()
        assert text.count("\n") <= 500, f"{name}: {text.count(chr(10))} lines"
        for node in ast.walk(ast.parse(text)):
            if isinstance(node, ast.ClassDef):
                size = node.end_lineno - node.lineno + 1
                assert size < 300, f"{name}.{node.name}: {size} lines"


def test_docking_has_its_wings_each_a_package_with_a_docstring_only():
    """Every module of `drake_dock.docking` lies in one of the wings; each wing's __init__.py is a
    docstring (what it holds, what it may import) and nothing else: no code, no re-export."""
    docking = PACKAGE / "docking"
    assert {p.name for p in docking.iterdir() if p.is_dir() and p.name != "__pycache__"} \
        == set(WINGS)
    assert [p.name for p in docking.glob("*.py")] == ["__init__.py"]
    for wing in (docking, *(docking / w for w in WINGS)):
        tree = ast.parse((wing / "__init__.py").read_text())
        assert ast.get_docstring(tree), wing
        assert len(tree.body) == 1, f"{wing}/__init__.py holds more than its docstring"


def test_module_names_are_unique():
    """No module of `drake_dock.docking` or of the layers above it shares its file name with
    another module (packages' faces and ``__main__`` apart), so that a name says one thing
    wherever it is met."""
    seen = {}
    for path in sorted(PACKAGE.rglob("*.py")):
        if path.name not in ("__init__.py", "__main__.py"):
            seen.setdefault(path.name, []).append(str(path.relative_to(PACKAGE)))
    twice = {n: p for n, p in seen.items() if len(p) > 1 and not all(
        q.split("/")[0] in ("core", "systems") for q in p)}
    assert not twice, twice


def _stem(name: str) -> str:
    """A module name without its inflection: "handovers" and "handover", "tracking" and
    "tracked", "loads" and "loading", "sample" and "sampling" share a stem."""
    for suffix in ("ing", "ed", "s"):
        if name.endswith(suffix) and len(name) - len(suffix) >= 4:
            name = name[:-len(suffix)]
            break
    return name[:-1] if name.endswith("e") and len(name) >= 5 else name


# A compiled kernel and its Python interface (which packs the patches and poses, raises the
# typed errors, and for covers holds the record and builds a cover from a patch's Python jets).
KERNEL_TWINS = [{"core/couple.py", "core/kernels/couples.py"},
                {"core/covers.py", "core/kernels/cover.py"},
                {"core/seeking.py", "core/kernels/seek.py"}]


def test_no_two_modules_are_inflections_of_one_name():
    """Two modules whose names differ only by an inflection (a plural, "-ing", "-ed") say the
    same thing for different contents, wherever they are; the kernel twins apart."""
    by_stem = {}
    for path in sorted(PACKAGE.rglob("*.py")):
        if path.name not in ("__init__.py", "__main__.py"):
            by_stem.setdefault(_stem(path.stem), set()).add(str(path.relative_to(PACKAGE)))
    clashes = [sorted(paths) for paths in by_stem.values()
               if len({Path(p).stem for p in paths}) > 1 and paths not in KERNEL_TWINS]
    assert not clashes, clashes


def test_an_impact_is_made_in_one_place_and_no_caller_writes_a_system_s_private_fields():
    """`Impact` records are constructed only in systems/impacts.py; no module reaches into
    another object's private attributes of the contact system's state (``x._mode_index`` for
    an ``x`` other than ``self``), and none writes a private attribute of an object other
    than ``self`` or ``cls``."""
    made, reached = [], []
    for name, path in _modules().items():
        for node in ast.walk(ast.parse(path.read_text())):
            if isinstance(node, ast.Call):
                f = node.func
                called = f.id if isinstance(f, ast.Name) else getattr(f, "attr", None)
                if called == "Impact" and name != "drake_dock.systems.impacts":
                    made.append(name)
            if isinstance(node, ast.Attribute) and node.attr == "_mode_index" and not (
                    isinstance(node.value, ast.Name) and node.value.id == "self"):
                reached.append(name)
            # nor writes another object's private attribute (``E._table = ...``)
            targets = (node.targets if isinstance(node, ast.Assign) else [node.target]
                       if isinstance(node, (ast.AugAssign, ast.AnnAssign)) else [])
            reached += [f"{name}:{node.lineno}" for t in targets for a in ast.walk(t)
                        if isinstance(a, ast.Attribute) and a.attr.startswith("_")
                        and not a.attr.startswith("__")
                        and not (isinstance(a.value, ast.Name) and a.value.id in ("self", "cls"))]
    assert not made and not reached, (made, reached)


def _reachable(start_files):
    """Every module (internal or external top-level name) reachable from the files' imports."""
    mods = _modules()
    seen, todo, external = set(), [], set()

    def add(path, package):
        for mod, names in _imports(path, package):
            hit = None
            for cand in [f"{mod}.{n}" for n in names] + [mod]:
                if cand in mods:
                    hit = cand
                    break
            if hit is None:
                external.add(mod.split(".")[0])
                continue
            parts = hit.split(".")       # importing a.b.c runs a/__init__ and a.b/__init__
            for k in range(1, len(parts) + 1):
                m = ".".join(parts[:k])
                if m in mods and m not in seen:
                    seen.add(m)
                    todo.append(m)

    for f in start_files:
        add(f, "tests")
    while todo:
        m = todo.pop()
        p = mods[m]
        add(p, m if p.name == "__init__.py" else m.rsplit(".", 1)[0])
    return seen, external


def test_core_tests_reach_no_drake():
    files = sorted((ROOT / "tests" / "core").glob("*.py"))    # conftest imports in fixtures
    seen, external = _reachable(files)
    assert "pydrake" not in external, sorted(m for m in seen)
    assert not [m for m in seen if m.split(".")[1:2] and _layer(m)[0] > LAYERS["docking"]]


@pytest.mark.parametrize("layer", ["core"])
def test_core_modules_use_numpy_and_scipy_only(layer):
    allowed = {"numpy", "scipy", "numba", "__future__", "dataclasses", "math", "functools",
               "itertools", "enum", "typing", "collections", "contextlib", "time", "copy",
               "os", "pathlib", "hashlib", "importlib",   # the compile cache's directory
               "ast", "tempfile", "fcntl",                # its keys, its fallback, its lock
               "argparse", "select", "subprocess", "sys",  # the parallel compile
               "queue", "threading", "signal"}            # fed from a thread
    for name, path in _modules().items():
        if name.split(".")[1:2] == [layer]:
            package = name if path.name == "__init__.py" else name.rsplit(".", 1)[0]
            for mod, _ in _imports(path, package):
                top = mod.split(".")[0]
                assert top == "drake_dock" or top in allowed, f"{name} imports {mod}"


def test_compiled_code_sorts_by_argsort_only():
    """numba names the machine code of its np.sort and its np.argsort of one array type alike,
    per process, so a kernel compiled in a process that loaded another from the cache can link
    one in place of the other (docs/performance.md, "Compiled kernels"). The compiled code -
    the kernels package but its compile infrastructure, and the modules of `register_jitable`
    functions - therefore calls np.argsort and never np.sort or an array's sort()."""
    kernels = PACKAGE / "core" / "kernels"
    infrastructure = {"__init__", "__main__", "compile_cache", "prepare"}
    compiled = [p for p in sorted(kernels.glob("*.py")) if p.stem not in infrastructure]
    compiled += [p for p in sorted(PACKAGE.rglob("*.py"))
                 if p.parent != kernels and "register_jitable" in p.read_text()]
    assert len(compiled) > 20
    sorts = [f"{p.relative_to(ROOT)}:{node.lineno}"
             for p in compiled for node in ast.walk(ast.parse(p.read_text()))
             if isinstance(node, ast.Call) and isinstance(node.func, ast.Attribute)
             and node.func.attr == "sort"]
    assert not sorts, f"np.sort or sort() in compiled code: {sorts}"


def _is_scalar_constant(node) -> bool:
    """A number, or np.inf / np.nan, possibly negated."""
    if isinstance(node, ast.UnaryOp):
        node = node.operand
    return (isinstance(node, ast.Constant) and isinstance(node.value, (int, float))
            or isinstance(node, ast.Attribute) and node.attr in ("inf", "nan"))


def test_kernels_copy_arrays_without_slice_assignment():
    """numba checks the shapes of an array assigned into a slice with an error message it
    formats at run time, which compiles its string formatting into each kernel holding one
    (docs/performance.md, "Compiled kernels"): the compiled functions copy with
    `copies.copy1`/`copy2` and assign only constants to slices. (An array assigned to an
    indexed row, R[k] = M, has the same check; read from the sources, only the slice forms
    are caught here.)"""
    kernels = PACKAGE / "core" / "kernels"
    infrastructure = {"__init__", "__main__", "compile_cache", "prepare"}
    found = []
    for p in sorted(kernels.glob("*.py")):
        if p.stem in infrastructure:
            continue
        jitted = [f for f in ast.parse(p.read_text()).body if isinstance(f, ast.FunctionDef)
                  and any("jit" in ast.unparse(d) for d in f.decorator_list)]
        for node in (n for f in jitted for n in ast.walk(f)):
            targets = node.targets if isinstance(node, ast.Assign) else []
            for t in targets:
                elts = t.elts if isinstance(t, ast.Tuple) else [t]
                for e in elts:
                    if (isinstance(e, ast.Subscript)
                            and any(isinstance(s, ast.Slice) for s in ast.walk(e.slice))
                            and not _is_scalar_constant(node.value)):
                        found.append(f"{p.relative_to(ROOT)}:{node.lineno}")
    assert not found, f"an array assigned into a slice in the kernels: {found}"
