"""GraphDistNet's loss (gdnplan.train.loss): hand-computed values and bad weights."""

import pytest
import torch

from gdnplan.errors import InputError
from gdnplan.train import GraphDistNetLoss, distance_loss, gradient_loss


def test_contact_weighted_distance_loss_by_hand():
    d = torch.tensor([0.0, 1.0])  # a contact sample and one 1 m away
    d_hat = torch.tensor([0.2, 1.4])  # squared errors 0.04 and 0.16 (scale 1)
    plain = GraphDistNetLoss()
    assert float(distance_loss(d_hat, d, plain, 1.0)) == pytest.approx(0.10)
    weighted = GraphDistNetLoss(contact_weight=3.0, contact_scale=0.02)  # w = 4 and ≈ 1
    assert float(distance_loss(d_hat, d, weighted, 1.0)) == pytest.approx((4 * 0.04 + 0.16) / 5)
    assert float(distance_loss(d_hat, d, plain, 2.0)) == pytest.approx(0.10 / 4)


def test_gradient_loss_with_slope_term_by_hand():
    g = torch.tensor([[3.0, 4.0], [1.0, 0.0], [0.0, 0.0]])  # |g| = 5, 1; a zero label left out
    g_hat = torch.tensor([[6.0, 8.0], [0.0, 2.0], [1.0, 1.0]])  # cos 1 (|ĝ| 10), cos 0 (|ĝ| 2)
    cosine = GraphDistNetLoss(grad_weight=0.5)
    assert float(gradient_loss(g_hat, g, cosine, 2.0)) == pytest.approx(0.5 * (0 + 1) / 2)
    slope = GraphDistNetLoss(grad_weight=0.5, grad_norm_weight=0.1)  # ((10−5)/2)², ((2−1)/2)²
    expected = (0.5 * (0 + 1) + 0.1 * (6.25 + 0.25)) / 2
    assert float(gradient_loss(g_hat, g, slope, 2.0)) == pytest.approx(expected)


@pytest.mark.parametrize(
    ("changes", "field"),
    [
        ({"contact_weight": -1.0}, "contact_weight"),
        ({"contact_scale": 0.0}, "contact_scale"),
        ({"grad_norm_weight": 1.0}, "grad_norm_weight"),  # without the gradient loss
        ({"grad_weight": -0.1}, "grad_weight"),
        ({"grad_weight": float("nan")}, "grad_weight"),
        ({"grad_weight": "x"}, "grad_weight"),
    ],
)
def test_bad_loss_weights_name_the_field(changes, field):
    with pytest.raises(InputError, match=field):
        GraphDistNetLoss(**changes)


def test_loss_reads_the_weights_of_an_old_flat_card():
    flat = {"layers": 2, "grad_weight": 0.1, "grad_norm_weight": 1.0, "contact_weight": 10}
    assert GraphDistNetLoss.from_dict(flat) == GraphDistNetLoss(0.1, 1.0, 10, 0.02)
