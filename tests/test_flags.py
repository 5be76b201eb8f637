"""One rule for on/off settings (gdnplan.flags.check_flag): a Python or numpy bool is a flag
(given back as a Python bool), 0/1, strings and None (unless optional) are not — at every
check of the package."""

import json
import warnings
from dataclasses import asdict

import numpy as np
import pytest
from hypothesis import example, given, settings
from hypothesis import strategies as st

import gdnplan as gp
from gdnplan.arm3d import Scene3D, box_obstacle, checker3d, load_robot3d
from gdnplan.casadi_bridge import DistanceCallback
from gdnplan.ccd import certify_path
from gdnplan.data.sampling import make_shard
from gdnplan.errors import InputError
from gdnplan.flags import check_flag
from gdnplan.models import fields
from gdnplan.models import settings as model_settings
from gdnplan.models.graphdistnet import GraphDistNetConfig
from gdnplan.ompl_planner import plan_ompl
from gdnplan.paper_figures import fig5
from gdnplan.train.graphdistnet import TrainConfig
from gdnplan.trajopt.config import IpoptConfig, RefineConfig
from gdnplan.trajopt.options import TrajoptOptions

SCENE = gp.make_scene("a")
SCENE3D = Scene3D(load_robot3d("ur5e"), [box_obstacle((0.1, 0.1, 0.1), (0.5, 0.0, 0.3))])
FLAGS = st.sampled_from([True, False, np.True_, np.False_]) | st.builds(
    lambda b: np.array([b])[0], st.booleans()
)
NOT_FLAGS = st.one_of(
    st.integers(-2, 2),
    st.sampled_from([np.int64(1), np.int8(0), 1.0, 0.0, "yes", "no", "false", "", [], [True]]),
    st.text(max_size=3),
    st.none(),
)


def sites():
    """Every flag check: a function of the value, raising or returning what was kept."""
    q = np.zeros((2, 2))
    return {
        "flags.check_flag": lambda v: check_flag(v, "x"),
        "models.settings.check_flag": lambda v: model_settings.check_flag(v, "x"),
        "models.fields.check_flag": lambda v: fields.check_flag("x", v),
        "GraphDistNetConfig.two_way": lambda v: GraphDistNetConfig(two_way=v).two_way,
        "RefineConfig.polish": lambda v: RefineConfig(polish=v).polish,
        "IpoptConfig.per_link": lambda v: IpoptConfig(per_link=v).per_link,
        "TrajoptOptions.ccd": lambda v: _options(ccd=v).ccd,
        "certify_path stop_early": lambda v: certify_path(SCENE, q, stop_early=v) and v,
        "DistanceCallback per_link": lambda v: (
            DistanceCallback("f", gp.CoalModel(), SCENE, 1, per_link=v) and v
        ),
        "signed_distance per_link": lambda v: gp.signed_distance(SCENE, q, per_link=v).ndim == 2,
        "Checker3D per_link": lambda v: _evaluate3d(per_link=v).distance.ndim == 2,
        "Checker3D broad_phase": lambda v: _evaluate3d(broad_phase=v) is not None and v,
        "Checker3D gradient": lambda v: _evaluate3d(gradient=v).gradient is not None,
        "TrainConfig.compile": lambda v: TrainConfig(compile=v).compile,
    }


def _evaluate3d(**flags):
    return checker3d(SCENE3D).evaluate(np.zeros((1, 6)), **flags)


def _options(**kwargs):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", DeprecationWarning)
        return TrajoptOptions(**kwargs)


@settings(max_examples=10, deadline=None)
@given(value=FLAGS)
@example(value=np.True_)  # audit: refused by every check but the CasADi callback's
@example(value=np.array([1.0, -1.0])[0] > 0)  # a comparison's result
def test_python_and_numpy_bools_are_flags_everywhere(value):
    for name, site in sites().items():
        kept = site(value)
        assert kept == bool(value), name
    for kept in (
        check_flag(value, "x"),
        GraphDistNetConfig(two_way=value).two_way,
        RefineConfig(polish=value).polish,
    ):
        assert type(kept) is bool  # stored as a Python bool: configs stay JSON-serialisable
    json.dumps(asdict(RefineConfig(ccd=value, polish=value)))


@settings(max_examples=20, deadline=None)
@given(value=NOT_FLAGS)
@example(value=1)  # audit: an int flag is a mistake, not True
@example(value=np.int64(0))
@example(value="no")  # true to Python
def test_other_values_are_refused_naming_the_setting(value):
    for name, site in sites().items():
        if value is None and name == "IpoptConfig.per_link":
            continue  # None: decided by the model (its documented default)
        with pytest.raises(InputError, match=r"expected (True or False|true or false)"):
            site(value)


def test_optional_flags_take_none_and_name_it():
    assert check_flag(None, "fused", optional=True) is None
    assert model_settings.check_flag(None, "fused", optional=True) is None
    with pytest.raises(InputError, match=r"^fused: expected True, False or None, got 1$"):
        model_settings.check_flag(1, "fused", optional=True)
    with pytest.raises(InputError, match=r"^ccd: expected true or false, got 'yes'$"):
        check_flag("yes", "ccd", lowercase=True)


@pytest.mark.parametrize("value", [1, "no", None, np.int64(0)])
def test_flags_of_long_calls_are_checked_before_the_work(value, tmp_path):
    q = np.zeros(2)
    with pytest.raises(InputError, match=r"^simplify: expected True or False"):
        plan_ompl(SCENE, q, q, 0.0, simplify=value)
    with pytest.raises(InputError, match=r"^progress: expected True or False"):
        fig5("a", progress=value)
    with pytest.raises(InputError, match=r"^compact: expected True or False"):
        make_shard("a", 0, 0, 2).save(tmp_path / "x.npz", compact=value)
    assert not (tmp_path / "x.npz").exists()
