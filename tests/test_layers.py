"""Layers: imports inside gdnplan only point down, and no imports form a cycle.

Every module of ``gdnplan/`` is read as text (``ast``, nothing is imported): its ``import`` and
``from … import`` statements at module level, in functions and under ``if TYPE_CHECKING:``,
relative and absolute, plus string constants that name a module of the package (a registry's
declared built-ins, an ``importlib.import_module`` argument). A module may import modules of
its own layer and of lower ones; the imports must form no cycle; every module must be in a
layer, so a new module is placed deliberately. The table is DESIGN.md's "Layers" section.
"""

from __future__ import annotations

import ast
from dataclasses import dataclass
from pathlib import Path

PACKAGE = "gdnplan"
ROOT = Path(__file__).resolve().parent.parent / PACKAGE

# Low → high. Names are relative to the package; "x.*" is every module inside package x;
# "__init__" is the package itself (gdnplan/__init__.py: lazy public names, built-in declarations).
LAYERS: list[tuple[str, tuple[str, ...]]] = [
    (
        "core",
        (
            "errors",
            "limits",
            "flags",  # the one check of an on/off setting
            "input_files",  # input files read whole, bounded
            "files",
            "assets",
            "convex_hulls",  # 2-D convex hulls: simplified, enclosing
            "geometry",
            "registry",
            "planar_chain",  # the plane rotations of a planar robot's chain
            "robot_checks",  # joint-angle batches and seeds of robot calls
            "robot_plane",  # the planning plane, link polygons, joint axes
            "robot",
            "urdf_robot",
            "urdf_robot.*",
            "planar",
            "robot_file",
            "obstacle_draws",  # random squares and α-shapes of the planar environments
            "scene_checks",  # a planar scene's robot, obstacles and problem-file tables
            "scene",
            "ur5e.kinematics",  # the UR5e/UR5 robot model: core robot modelling
            "ur5e.gripper",
            "ur5e.urdf",
            "ur5e.arms",
            "ur5e.ik",
            "ur5e.layout",  # fetch layouts: plane polygons and tcp targets, no distances
            "arm3d.shape_numbers",  # coordinates, sizes and point sets of 3-D shapes
            "arm3d.poses",  # positions and rotations of 3-D shapes
            "arm3d.shapes",
            "arm3d.pairs",
            "arm3d.link_shape",  # one link's collision shape, checked when made
            "arm3d.robot3d",
            "arm3d.builtin",
            "arm3d.scene3d",
            "arm3d.cloud3d",  # point clouds as coal octrees (validated), no distances
            "arm3d.storage3d",  # the 3-D fetch storage: boxes and tool poses, no distances
            "arm3d.fk3d",  # batched forward kinematics in numpy
        ),
    ),
    (
        "exact geometry and seeds",
        # ur5e (the package) re-exports the fetch scene, which keeps coal-clear poses
        (
            "distance",
            "ccd_motion",  # the planar lever arms and motion bound of the certificate
            "ccd",
            "ccd_curve",
            "ccd_contact",
            "rrt",
            "ur5e",
            "ur5e.scene",
            "ur5e.plot",
            "arm3d",
            "arm3d.distance3d",
            "arm3d.narrow3d",  # the pair table and coal's narrow phase of one pair
            "arm3d.gradient3d",  # the exact gradient of a pair's distance
            "arm3d.ccd3d",
            "arm3d.depth3d",  # proven bounds on overlapping pairs (the contact certificate)
            "arm3d.ik3d_checks",  # the pose IK's settings and tool positions
            "arm3d.ik3d",
            "arm3d.held",
            "arm3d.fetch3d_scene",
            "arm3d.scene_file3d",  # 3-D problem-file tables -> Scene3D (pose goals by IK)
            "arm3d.shape_file3d",  # posed-shape tables (obstacles, the held object)
            "arm3d.robot_file3d",  # the [robot] table of 3-D files, a held object
            "arm3d.write_file3d",  # Scene3D -> 3-D problem-file text
            "exact",  # the exact-geometry protocol of planar and 3-D scenes
            "path_metrics",
            "ompl_planner",
        ),
    ),
    (
        "graphs",
        (
            "graph",  # re-exports the three below
            "graph_batch",  # padded batches of ring graphs
            "graph_obstacles",
            "graph_robot",
            "graph3d",  # re-exports the three below
            "graph3d_shapes",  # shapes -> nodes, polytope and kNN edges, neighbourhoods
            "graph3d_robot",
            "graph3d_obstacles",
        ),
    ),
    ("models", ("models", "models.*")),
    ("casadi bridge", ("casadi_bridge",)),
    (
        "trajopt",
        (
            "trajopt",
            "trajopt.*",
            "timing",
            "timing_checks",
            "timing_profiles",
            "timing_toppra",
            "arm3d.problem3d",
        ),
    ),
    ("training", ("data", "data.*", "metrics", "train", "train.*", "train_clearancenet")),
    (
        "paper reproduction",
        (
            "env_models",
            "evaluate",
            "paper_figures",
            "table1_rows",
            "table1_text",
            "table2",
            "table2_records",
            "table2_text",
            "ablation",
            "ablation_steps",
            "ablation_scores",
            "ablation_table",
            "fetch",
            "arm3d.fetch3d",
            "arm3d.fetch3d_files",
            "viz",
            "viz3d",
            "viz3d.*",
        ),
    ),
    ("cli", ("cli", "cli.*", "__init__", "__main__")),
]


@dataclass(frozen=True)
class Import:
    """``source`` imports ``target`` (full dotted names) at line ``line`` of ``source``."""

    source: str
    target: str
    line: int


def short(module: str) -> str:
    """``gdnplan.models.weights`` → ``models.weights``; the package itself → ``__init__``."""
    return "__init__" if module == PACKAGE else module.removeprefix(PACKAGE + ".")


def layer_of(module: str) -> int | None:
    """Index into LAYERS of ``module`` (a full name), None when no layer lists it."""
    name = short(module)
    for i, (_, members) in enumerate(LAYERS):
        for m in members:
            if name == m or (m.endswith(".*") and name.startswith(m[:-1])):
                return i
    return None


def describe(module: str) -> str:
    i = layer_of(module)
    return f"{short(module)} (layer {i} {LAYERS[i][0]})" if i is not None else short(module)


def file_of(module: str, modules: set[str]) -> str:
    """The path of ``module`` in the source tree (a package is its ``__init__.py``)."""
    path = module.replace(".", "/")
    return f"{path}/__init__.py" if is_package(module, modules) else f"{path}.py"


def is_package(module: str, modules: set[str]) -> bool:
    return module == PACKAGE or any(m.startswith(module + ".") for m in modules)


def resolve(name: str, modules: set[str]) -> str | None:
    """The longest known module that ``name`` (a dotted name) is or lies inside, if any."""
    parts = name.split(".")
    for k in range(len(parts), 0, -1):
        if ".".join(parts[:k]) in modules:
            return ".".join(parts[:k])
    return None


def imports(module: str, source: str, modules: set[str]) -> list[Import]:
    """Every import of a package module by ``module`` (its text ``source``), any nesting."""
    package = module if is_package(module, modules) else module.rpartition(".")[0]
    found: list[Import] = []

    def add(name: str, line: int) -> None:
        target = resolve(name, modules)
        if target is not None and target != module and Import(module, target, line) not in found:
            found.append(Import(module, target, line))

    tree = ast.parse(source)
    logger_names = {  # logging.getLogger("gdnplan.x") names a logger, not an import
        id(call.args[0])
        for call in ast.walk(tree)
        if isinstance(call, ast.Call)
        and isinstance(call.func, ast.Attribute)
        and call.func.attr == "getLogger"
        and call.args
    }
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            for alias in node.names:
                add(alias.name, node.lineno)
        elif isinstance(node, ast.ImportFrom):
            if node.level:
                base = package.split(".")[: len(package.split(".")) - node.level + 1]
                origin = ".".join(base + ([node.module] if node.module else []))
            else:
                origin = node.module or ""
            for alias in node.names:  # `from pkg import submodule` imports the submodule
                sub = f"{origin}.{alias.name}"
                add(sub if sub in modules else origin, node.lineno)
        elif isinstance(node, ast.Constant) and isinstance(node.value, str):
            if id(node) not in logger_names and node.value in modules - {
                PACKAGE
            }:  # a module named by a string: imported on demand
                add(node.value, node.lineno)
    return found


def find_cycle(edges: list[Import]) -> list[Import] | None:
    """One import cycle (its edges in order), or None: a depth-first search."""
    out: dict[str, list[Import]] = {}
    for e in edges:
        out.setdefault(e.source, []).append(e)
    state: dict[str, int] = {}  # 1 on the stack, 2 done
    stack: list[Import] = []

    def visit(node: str) -> list[Import] | None:
        state[node] = 1
        for e in out.get(node, []):
            if state.get(e.target) == 1:
                start = next((i for i, s in enumerate(stack) if s.source == e.target), len(stack))
                return [*stack[start:], e]
            if e.target not in state:
                stack.append(e)
                found = visit(e.target)
                if found:
                    return found
                stack.pop()
        state[node] = 2
        return None

    for node in sorted(out):
        if node not in state:
            found = visit(node)
            if found:
                return found
    return None


def check(sources: dict[str, str]) -> list[str]:
    """Problems of the package whose modules are ``sources`` (full name → source text):
    modules in no layer, imports that point up, and one import cycle if there is any."""
    modules = set(sources)
    problems = [
        f"{file_of(m, modules)}: module {short(m)} is in no layer; place it in LAYERS "
        "(tests/test_layers.py) and DESIGN.md's Layers"
        for m in sorted(modules)
        if layer_of(m) is None
    ]
    edges = [e for m in sorted(modules) for e in imports(m, sources[m], modules)]
    for e in edges:
        lo, hi = layer_of(e.source), layer_of(e.target)
        if lo is not None and hi is not None and hi > lo:
            problems.append(
                f"{describe(e.source)} imports {describe(e.target)} (higher layer) at "
                f"{file_of(e.source, modules)}:{e.line}"
            )
    cycle = find_cycle(edges)
    if cycle:
        path = " → ".join([short(cycle[0].source), *(short(e.target) for e in cycle)])
        where = ", ".join(f"{file_of(e.source, modules)}:{e.line}" for e in cycle)
        problems.append(f"import cycle {path} ({where})")
    return problems


def package_sources() -> dict[str, str]:
    """Full module name → source text of every module of gdnplan/."""
    out = {}
    for path in sorted(ROOT.rglob("*.py")):
        parts = path.relative_to(ROOT.parent).with_suffix("").parts
        name = ".".join(parts[:-1] if parts[-1] == "__init__" else parts)
        out[name] = path.read_text(encoding="utf-8")
    return out


# -------------------------------------------------------------------- the package
def test_imports_point_down_without_cycles_and_every_module_has_a_layer():
    problems = check(package_sources())
    assert not problems, "\n".join(problems)


def test_every_layer_entry_names_a_module():
    names = {short(m) for m in package_sources()}
    for _, members in LAYERS:
        for m in members:
            found = any(n.startswith(m[:-1]) for n in names) if m.endswith(".*") else m in names
            assert found or m.endswith(".*"), f"LAYERS lists {m}, which is not a module"


def test_no_module_imports_the_cli():
    sources = package_sources()
    edges = [e for m in sources for e in imports(m, sources[m], set(sources))]
    assert len(edges) > 100  # the scan sees the package's imports
    cli = f"{PACKAGE}.cli"
    entry = f"{PACKAGE}.__main__"  # ``python -m gdnplan`` runs the command
    inside = [e for e in edges if e.source in (cli, entry) or e.source.startswith(cli + ".")]
    assert inside  # the cli package's own modules import each other
    outside = [e for e in edges if e not in inside]
    assert not [e for e in outside if e.target == cli or e.target.startswith(cli + ".")]


# -------------------------------------------------------------------- the checker
def fake_package(**changes: str) -> dict[str, str]:
    """The package's sources with some modules' text replaced (short name → text)."""
    sources = package_sources()
    for name, text in changes.items():
        sources[f"{PACKAGE}.{name.replace('__', '.')}"] = text
    return sources


def test_checker_reports_an_upward_import_with_its_place():
    problems = check(fake_package(geometry="import numpy\n\nfrom .cli import run\n"))
    assert "geometry (layer 0 core) imports cli (layer 8 cli) (higher layer) at " in problems[0]
    assert problems[0].endswith("gdnplan/geometry.py:3")


def test_checker_sees_function_level_absolute_and_submodule_imports():
    text = (
        "def f():\n"
        "    from gdnplan.models.weights import read_card\n"
        "    from gdnplan import evaluate\n"
        "    import gdnplan.trajopt\n"
    )
    problems = check(fake_package(scene=text))
    ups = {p.split(" imports ")[1].split(" (")[0] for p in problems if "higher layer" in p}
    assert ups == {"models.weights", "evaluate", "trajopt"}


def test_checker_sees_a_module_named_by_a_string():
    problems = check(fake_package(robot='BUILTINS = ("gdnplan.ur5e",)\n'))
    assert any("robot (layer 0 core) imports ur5e" in p for p in problems)


def test_checker_reports_a_cycle_within_a_layer():
    problems = check(
        fake_package(
            ccd="from .rrt import seed_path\n", rrt="def f():\n    from .ccd import verify_path\n"
        )
    )
    assert any(p.startswith("import cycle ccd → rrt → ccd") for p in problems), problems


def test_checker_reports_a_module_in_no_layer():
    problems = check(fake_package(helpers="from .errors import InputError\n"))
    assert problems == [
        "gdnplan/helpers.py: module helpers is in no layer; place it in LAYERS "
        "(tests/test_layers.py) and DESIGN.md's Layers"
    ]


def test_relative_imports_resolve_from_a_subpackage():
    text = "from ..scene import Scene\nfrom .threads import check_threads\nfrom . import weights\n"
    got = {e.target for e in imports("gdnplan.models.checks", text, set(package_sources()))}
    assert got == {"gdnplan.scene", "gdnplan.models.threads", "gdnplan.models.weights"}
