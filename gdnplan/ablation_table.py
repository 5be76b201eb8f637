"""The ablation's markdown table and notes (:func:`markdown`)."""

from __future__ import annotations

import numpy as np

from .ablation_steps import PATIENCE, STEPS, Settings

__all__ = ["markdown", "notes"]


def _mean_se(values: list[float], fmt: str) -> str:
    v = np.asarray(values, float)
    if len(v) < 2:
        return format(v.mean(), fmt)
    return f"{format(v.mean(), fmt)} ± {format(v.std(ddof=1) / np.sqrt(len(v)), fmt)}"


def markdown(results: dict[str, list[list[dict]]], s: Settings) -> str:
    """The ablation table (one row per environment and step) and its notes."""
    head = ("| env | step | change | MAE (mm) | AUC | ACD | d̂+∇ (ms/config) | sweep max (cm) "
            "| Table II Ipopt | median (s) | median CPU (s) | train s (epochs) |")  # fmt: skip
    lines = [head, "|" + "---|" * 12]
    for env, steps in results.items():
        for (name, change, _), runs in zip(STEPS, steps, strict=True):
            if not runs:
                lines.append(f"| {env} | {name} | {change} |" + " not trained yet |" * 9)
                continue
            t2 = "–", "–", "–"
            if all("t2_success" in r for r in runs):
                ok, n = sum(r["t2_success"] for r in runs), sum(r["t2_n"] for r in runs)
                cpu = [r["t2_cpu"] for r in runs if "t2_cpu" in r]
                t2 = (f"{ok}/{n}", f"{np.median([r['t2_median'] for r in runs]):.2f}",
                      f"{np.median(cpu):.2f}" if len(cpu) == len(runs) else "–")  # fmt: skip
            lines.append(
                f"| {env} | {name} | {change} | {_mean_se([1e3 * r['mae'] for r in runs], '.2f')} "
                f"| {_mean_se([r['auc'] for r in runs], '.4f')} "
                f"| {_mean_se([r['acd'] for r in runs], '.3f')} "
                f"| {1e3 * np.mean([r['grad_time'] for r in runs]):.3f} "
                f"| {100 * max(r['sweep_max'] for r in runs):.2f} | {t2[0]} | {t2[1]} | {t2[2]} "
                f"| {np.mean([r['seconds'] for r in runs]):.0f} "
                f"({'/'.join(str(r['epochs']) for r in runs)}) |"
            )
    n_test = sorted({r["n_test"] for steps in results.values() for runs in steps for r in runs})
    return (
        "\n".join(lines) + "\n" + notes(s, "/".join(map(str, n_test)), tuple(results))
        + _short(results, s)
        + _versions(results, "t2_git", "Table II rows were solved by", "planner",
                    "delete the `.scores.json` files to re-score")
        + _versions(results, "time_git", "d̂+∇ was measured by", "code",
                    "`--retime` measures every kept step again")
    )  # fmt: skip


def _short(results: dict[str, list[list[dict]]], s: Settings) -> str:
    """A note naming the rows with a seed trained for other than the environment's epochs
    (kept from an earlier budget, until a run trains them to it)."""
    rows = [f"{env} {name}" for env, steps in results.items()
            for (name, _, _), runs in zip(STEPS, steps, strict=True)
            if any(r["epochs"] != s.epochs_of(env) for r in runs)]  # fmt: skip
    if not rows:
        return ""
    return (f"Not yet at the epochs above (kept from an earlier budget; the last column says "
            f"how many): {', '.join(rows)}.\n")  # fmt: skip


def _versions(
    results: dict[str, list[list[dict]]], key: str, lead: str, what: str, fix: str
) -> str:
    """A note naming the code versions (``key``: a git SHA in the scores; rows scored before it
    was recorded: "before <key>") behind a column when there is more than one."""
    column = "t2_success" if key == "t2_git" else "grad_time"
    shas = {r[key][:7] if key in r else f"before {key}" for steps in results.values()
            for runs in steps for r in runs if column in r}  # fmt: skip
    if len(shas) < 2:
        return ""
    versions = ", ".join(sorted(shas))
    return (
        f"{lead} {len(shas)} {what} versions ({versions}): compare them within one version; "
        f"{fix}.\n"
    )


def notes(s: Settings, n_test: str, envs: tuple[str, ...]) -> str:
    epochs = ", ".join(f"{env} {s.epochs_of(env)}" for env in envs)
    return f"""
Notes: each step changes one field of the step above (`gdnplan.ablation.STEPS`). Every step
is trained from scratch on the same data (`data/<env>/train`, the shipped weights' share of
it) for the same number of Adam steps: {epochs} epochs (batch {s.batch}; early stopping
after {PATIENCE} epochs without a better validation MAE), with the paper's loss (squared
distance error only) and the same seeds; ± is the standard error over the seeds. Train s:
the CPU seconds those epochs took on one torch thread (the cost of a step's epochs).
MAE, AUC, ACD: the {n_test} samples of `data/<env>/test` (seed 1). d̂+∇: one batch of
{s.timing_batch} configurations of one scene, CPU time of the fastest of 5, one thread (the
default inference path: the compiled pass where it serves the network). Sweep max: the
largest change of d̂ between 0.003 rad steps along {s.sweep_steps}-step sweeps of every
joint from {s.sweeps} configuration(s), the largest over the seeds. Table II: Ipopt on the
environment's own reaching problems (b and d only), certified successes over all seeds, the
median wall time and the median CPU time of the planning process (the work: wall times of
rows scored while other jobs ran are longer; rows scored before it was recorded show "–").
"""
