"""What the commands share: option help texts, progress lines, thread settings, vectors from the
command line, scenes and starts from a problem file or a name."""

from __future__ import annotations

import logging
import sys
from pathlib import Path
from typing import TYPE_CHECKING

from ..errors import GdnplanError, InfeasibleProblemError, InputError, ProblemFileError

if TYPE_CHECKING:  # the commands import numpy and the library when they run: a fast --help
    import numpy as np

    from ..scene import Scene


WEIGHTS_HELP = (
    "GraphDistNet weights: a shipped name (d, ur5e, …) or a .safetensors file "
    "(default: the shipped weights for the problem's robot and obstacles)."
)


PROBLEM_HELP = "A problem TOML file or a shipped problem's name (fetch_reach, planar7_d, …)."


QUIET_HELP = "No progress lines on stderr (warnings and errors only)."


class _StderrHandler(logging.StreamHandler):
    """Log records as bare lines on the ``sys.stderr`` of the moment (tests replace it)."""

    def __init__(self) -> None:
        super().__init__()
        self.setFormatter(logging.Formatter("%(message)s"))

    @property
    def stream(self):  # type: ignore[override]
        return sys.stderr

    @stream.setter
    def stream(self, value) -> None:  # StreamHandler.__init__ assigns one; stderr is used
        pass


def show_progress(on: bool) -> None:
    """Print the library's progress (the ``gdnplan`` logger's INFO lines: planner and fetch
    stages) to stderr, or only its warnings when ``on`` is False. Progress never goes to
    stdout, so ``--json`` output stays one JSON object. Undone by :func:`hide_progress`."""
    hide_progress()
    logger = logging.getLogger("gdnplan")
    logger.addHandler(_StderrHandler())
    logger.setLevel(logging.INFO if on else logging.WARNING)


def hide_progress() -> None:
    """Detach the handler of :func:`show_progress` (``run`` calls it as a command ends)."""
    logger = logging.getLogger("gdnplan")
    for old in [h for h in logger.handlers if isinstance(h, _StderrHandler)]:
        logger.removeHandler(old)
    logger.setLevel(logging.NOTSET)


THREADS_HELP = (
    "torch threads for learned models, 1 … max(256, 4 per core); 1 is fastest on a busy or "
    "2-core CPU."
)


def set_threads(threads: int, torch_global: bool = False) -> None:
    """The learned models' inference threads (:mod:`gdnplan.models.threads`) and, with
    ``torch_global`` (training, table runs), torch's own intra-op threads; InputError naming
    ``--threads`` unless threads is an integer in 1 … ``MAX_THREADS`` (4 per core, at least
    256; :func:`gdnplan.models.threads.check_threads`), checked before anything is set. Without
    ``torch_global`` torch is not imported (coal-only commands)."""
    from ..models.threads import check_threads, set_inference_threads

    threads = check_threads(threads, "--threads", default=False)
    set_inference_threads(threads)
    if torch_global:
        import torch

        torch.set_num_threads(threads)


def parse_vector(text: str, name: str) -> np.ndarray:
    """'0.1, -0.2, 0.3' (or '0.1 -0.2 0.3') -> array; raises InputError naming ``name``
    (an empty field, as in '0.6,,0', is refused, not skipped)."""
    import numpy as np

    fields = text.split(",") if "," in text else text.split()
    if any(not f.strip() for f in fields):
        raise InputError(f"{name}: an empty field in {text!r}; separate numbers by one comma")
    try:
        return np.array([float(v) for v in fields])
    except ValueError as e:
        raise InputError(f"{name}: expected numbers separated by commas, got {text!r}") from e


def scene_and_start(target: str, seed: int) -> tuple[Scene, np.ndarray | None]:
    """A scene from a problem file or shipped problem name (with its start q), or from a
    scene generator name."""
    from ..assets import problem_names
    from ..scene import make_scene, scene_names

    if (
        target.endswith(".toml")
        or target in problem_names()
        or (target not in scene_names() and Path(target).exists())
    ):
        return problem_scene_and_start(target)
    return make_scene(target, seed=seed), None


def problem_scene_and_start(path: str | Path) -> tuple[Scene, np.ndarray | None]:
    """The scene and ``[start] q`` of a problem file, checked as ``plan`` checks it (the one
    parser, :func:`gdnplan.trajopt.problem_tables`).

    A file with a ``[goal]`` passes every check of :meth:`Problem.from_config` except the
    feasibility ones (a start in collision is what ``show`` draws); a scene-only file (no
    ``[goal]``, ``[start]`` optional) the checks of its tables. ProblemFileError names the file.
    """
    from ..assets import problem_file
    from ..trajopt import Problem, _vector, problem_tables, read_problem_file

    cfg = read_problem_file(path)
    folder = problem_file(path).parent  # relative paths in the file ([robot] urdf) start here
    try:
        tables = problem_tables(cfg, base_dir=folder, require_goal="goal" in cfg)
        if tables.goal is not None:
            try:
                Problem.from_tables(tables)
            except InfeasibleProblemError:
                pass
        if tables.start is None:
            return tables.scene, None
        q = _vector(tables.start, tables.scene.robot.dof, "start.q")
        return tables.scene, check_limits(tables.scene.robot, q, "start.q")
    except GdnplanError as e:
        raise ProblemFileError(f"{path}: {e}") from e


def check_limits(robot, q: np.ndarray, name: str) -> np.ndarray:
    """``q`` (dof,) when it is within the robot's joint limits; InputError naming the joint."""
    from ..robot import first_outside

    j = first_outside(q, robot.lower, robot.upper)
    if j is not None:
        raise InputError(
            f"{name}[{j}] = {q[j]:.4g} is outside the joint limits "
            f"[{robot.lower[j]:.4g}, {robot.upper[j]:.4g}] of {robot.name}"
        )
    return q


def check_not_shipped(target: Path, replace: bool) -> None:
    """InputError when ``target`` (the weights to write) is an existing shipped weights file
    (``gdnplan.assets.WEIGHTS_DIR``; from the repository root ``weights/`` is that folder)
    and ``replace`` is off: a training run would silently change what every plan by that
    name uses and what the README's figures were measured with."""
    from ..assets import WEIGHTS_DIR

    resolved = target.resolve()
    shipped = WEIGHTS_DIR.resolve()
    pair = (resolved, resolved.with_suffix(".json"))
    if not replace and resolved.parent == shipped and any(p.exists() for p in pair):
        raise InputError(
            f"--out: {target} is a shipped weights file ({resolved.stem}); give another --out "
            "(e.g. my_weights.safetensors) or --replace-shipped to replace it"
        )
