"""Table I's rows: the paper's figures (:data:`PAPER`, Welch's p :data:`PAPER_P`), the names
of our GraphDistNet rows and their weights files, and Welch's p of a row's errors against
ClearanceNet's (:func:`welch_p`)."""

from __future__ import annotations

from .metrics import Result, welch_p_value

# Paper Table I: (time s, MAE, AUC, ACD); None where the paper has "-" or N/A.
PAPER: dict[str, dict[str, tuple]] = {
    "a": {
        "coal": (1.0653, None, None, None),
        "DiffCo": (0.0048, None, 1.0000, 0.3575),
        "ClearanceNet": (0.0009, 0.0082, 1.0000, 0.0255),
        "GraphDistNet": (0.0115, 0.0031, 1.0000, 0.0054),
    },
    "b": {
        "coal": (1.1822, None, None, None),
        "DiffCo (w/o AL)": (0.0054, None, 0.5031, 1.0270),
        "DiffCo (w/ AL)": (2058.2, None, 0.9948, 0.4221),
        "ClearanceNet": (0.0009, 0.1732, 0.9986, 0.2853),
        "GraphDistNet": (0.0115, 0.0390, 0.9999, 0.1748),
    },
    "c": {
        "coal": (3.1573, None, None, None),
        "DiffCo": (0.0740, None, 0.9843, 0.3202),
        "ClearanceNet": (0.0012, 0.2360, 0.9111, 0.5933),
        "GraphDistNet": (0.0574, 0.0253, 0.9990, 0.1458),
    },
    "d": {
        "coal": (4.4467, None, None, None),
        "DiffCo (w/o AL)": (0.0742, None, 0.5239, 0.9450),
        "DiffCo (w/ AL)": (75129.5, None, 0.9798, 0.3968),
        "ClearanceNet": (0.0012, 0.7725, 0.5691, 0.9491),
        "GraphDistNet": (0.0546, 0.1614, 0.9842, 0.4152),
    },
    "e": {
        "coal": (6.8432, None, None, None),
        "DiffCo (w/o AL)": (0.0350, None, 0.5200, 0.9612),
        "DiffCo (w/ AL)": (None, None, None, None),  # out of memory in the paper
        "ClearanceNet": (0.0011, 0.7479, 0.8882, 0.9767),
        "GraphDistNet": (0.1251, 0.2446, 0.9925, 0.8421),
    },
}
PAPER_P = {"a": 6e-20, "b": 2e-12, "c": 6e-60, "d": 1e-10, "e": 3e-2}

GDN = "GraphDistNet (gdnplan)"  # the shipped weights/<env>
FAITHFUL = "GraphDistNet (paper architecture, this implementation)"  # weights/<env>_faithful
FAITHFUL_DRAWS = 8  # first-layer draws averaged in the row below
FAITHFUL_MEAN = f"GraphDistNet (paper architecture, mean of {FAITHFUL_DRAWS} first-layer draws)"
PAPER_ROW = {GDN: "GraphDistNet", FAITHFUL: "GraphDistNet", FAITHFUL_MEAN: "GraphDistNet"}
GRAPHDISTNET_FILES = {
    GDN: "{env}.safetensors",
    FAITHFUL: "{env}_faithful.safetensors",
    FAITHFUL_MEAN: "{env}_faithful.safetensors",
}
DRAWS = {FAITHFUL_MEAN: FAITHFUL_DRAWS}  # rows whose d̂ is a mean over first-layer draws


def welch_p(rows: list[Result], method: str) -> float | None:
    """Welch's p of ``method``'s absolute errors vs ClearanceNet's (None without both)."""
    errors = {r.method: r.abs_error for r in rows if r.abs_error is not None}
    if method not in errors or "ClearanceNet" not in errors:
        return None
    return welch_p_value(errors[method], errors["ClearanceNet"])


__all__ = [
    "DRAWS",
    "FAITHFUL",
    "FAITHFUL_DRAWS",
    "FAITHFUL_MEAN",
    "GDN",
    "GRAPHDISTNET_FILES",
    "PAPER",
    "PAPER_P",
    "PAPER_ROW",
    "welch_p",
]
