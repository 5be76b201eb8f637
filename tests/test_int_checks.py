"""The one integer-range check (gdnplan.limits.check_int) behind planning limits, model config
fields, thread counts and training schedules: ints and numpy integers in range pass as ints;
bools, floats, strings and values out of range are InputErrors naming the field and the range."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest
from hypothesis import example, given, settings
from hypothesis import strategies as st

from gdnplan.errors import InputError
from gdnplan.limits import check_int, shown
from gdnplan.models import fields
from gdnplan.models import threads as th
from gdnplan.train.fit import FitConfig
from gdnplan.trajopt.config import CONFIG_TABLES


@pytest.mark.parametrize("value", [1, 5, np.int64(5), np.uint8(3), 10])
def test_integers_in_range_pass_as_ints(value):
    got = check_int(value, "n", 1, 10)
    assert got == value and type(got) is int


@pytest.mark.parametrize("value", [True, np.bool_(True), 2.0, np.float64(2.0), "2", None, [2]])
def test_non_integers_are_refused(value):
    with pytest.raises(InputError, match=r"^n: expected an integer in \[0, 10\], got "):
        check_int(value, "n", 0, 10)


@pytest.mark.parametrize("value", [-1, 11, np.int64(11), 10**5000], ids=lambda v: shown(v, 12))
def test_values_out_of_range_name_the_range(value):
    with pytest.raises(InputError, match=r"^n: expected an integer in \[0, 10\], got ") as e:
        check_int(value, "n", 0, 10)
    assert str(e.value).endswith(shown(value))


def test_no_upper_bound_and_a_note():
    assert check_int(10**30, "seed", 0) == 10**30
    with pytest.raises(InputError, match=r"^seed: expected an integer ≥ 0, got -1$"):
        check_int(-1, "seed", 0)
    with pytest.raises(InputError, match=r"^k: expected an integer in \[1, 4\] \(why\), got 5$"):
        check_int(5, "k", 1, 4, "why")


def test_numpy_scalars_show_as_python_values():
    assert shown(np.int64(7)) == "7" and shown(np.float32(0.5)) == "0.5"


def test_every_former_copy_uses_it():
    assert fields.check_int is check_int
    with pytest.raises(InputError, match=r"^mlp\[1\]: expected an integer in \[1, 4096\]"):
        fields.check_widths("mlp", [8, 0])
    assert th.check_threads(np.int64(2)) == 2 and type(th.check_threads(np.int64(2))) is int
    with pytest.raises(InputError, match=r"--threads: .*\(the limit: 4 per core, at least 256\), "):
        th.check_threads(0, "--threads", default=False)
    with pytest.raises(InputError, match=r"; or None: the default\), got 0$"):
        th.check_threads(0)
    config = FitConfig(batch=np.int64(8), seed=np.int32(3))
    assert (config.batch, config.seed) == (8, 3) and type(config.seed) is int
    with pytest.raises(InputError, match=r"^epochs: expected an integer ≥ 1, got 0$"):
        FitConfig(epochs=0)


@pytest.mark.parametrize("seed", [-1, True, 1.5, "0"], ids=repr)
def test_make_scene_seeds_use_it(seed):
    from gdnplan.scene import make_scene

    with pytest.raises(InputError, match=r"^seed: expected an integer ≥ 0, got "):
        make_scene("a", seed=seed)
    assert make_scene("a", seed=np.int64(3)).seed == 3


NUMPY_INTS = [np.int8, np.int16, np.uint8, np.uint16, np.int32, np.int64]


@settings(max_examples=40, deadline=None)
@given(kind=st.sampled_from(["seed", "refine", "ipopt", "adam"]), data=st.data())
@example(kind="ipopt", data=None)
def test_planner_configs_hold_python_scalars_whatever_the_caller_gave(kind, data):
    """A numpy scalar given for a planner setting is stored as its Python value: numpy
    integers keep their width, so IpoptConfig(interpolated=np.int8(50)) made int8 check-point
    counts that the refine rounds doubled past 127 to negative (the check points vanished)."""
    cls = CONFIG_TABLES[kind]
    if data is None:  # the crafted case: int8 check points doubled by the refine rounds
        cfg = cls(interpolated=np.int8(50))
        splits = np.full(4, cfg.interpolated + 1)
        assert np.all(splits * 2**8 > 0)
        return
    values = {}
    for item in dataclasses.fields(cls):
        default = getattr(cls(), item.name)
        if isinstance(default, bool):
            values[item.name] = np.bool_(default)
        elif isinstance(default, int):
            fits = [t for t in NUMPY_INTS if np.iinfo(t).max >= default]
            values[item.name] = data.draw(st.sampled_from(fits))(default)
        elif isinstance(default, float):
            values[item.name] = data.draw(st.sampled_from([np.float32, np.float64]))(default)
    cfg = cls(**values)
    for name, value in values.items():
        got = getattr(cfg, name)
        assert type(got) in (bool, int, float) and got == value.item()


def test_a_problem_holds_python_scalars():
    from gdnplan.trajopt import Problem

    base = Problem.from_toml("planar2_square")
    p = Problem(base.scene, base.start, base.goal, waypoints=np.int8(100), margin=np.float32(0.02),
                max_step=np.float64(1.0), clearance=np.float32(0.01))  # fmt: skip
    assert type(p.waypoints) is int and (p.waypoints - 1) * 60 == 5940  # int8 wrapped
    assert type(p.margin) is float and type(p.max_step) is float
