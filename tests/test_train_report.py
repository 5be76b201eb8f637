"""What a training run reports (gdnplan.train.report): the Table I metrics by hand."""

import numpy as np
import pytest

from gdnplan.train import metrics


def test_metrics_hand_computed():
    """MAE, AUC and ACD of four samples: a zero model gradient counts as cos = 0, a zero coal
    gradient is left out (as in gdnplan.evaluate)."""
    d = np.array([-0.02, 0.01, 0.05, 0.10])
    d_hat = np.array([-0.01, 0.03, 0.04, 0.10])
    g = np.array([[1.0, 0.0], [0.0, 2.0], [1.0, 1.0], [0.0, 0.0]])
    g_hat = np.array([[2.0, 0.0], [0.0, 0.0], [-1.0, -1.0], [1.0, 0.0]])
    m = metrics(d_hat, g_hat, d, g, reach=2.0, margin=0.0)
    assert m["mae_m"] == pytest.approx(0.01)
    assert m["mae_reach"] == pytest.approx(0.005)
    assert m["auc"] == 1.0  # the one colliding sample has the lowest d̂
    assert m["acd_n"] == 3
    assert m["acd"] == pytest.approx((0.0 + 1.0 + 2.0) / 3)
