"""GraphDistNet's training loss and its settings :class:`GraphDistNetLoss`.

Loss per sample (distances normalised by the network's ``scale`` = the arm's reach):

    L = w · ((d̂ − f) / scale)² / w̄ + λ · (1 − cos(∂d̂/∂q, ∂f/∂q))    (λ = ``grad_weight``, 0 = paper)
        [+ ν · ((|∂d̂/∂q| − |∂f/∂q|) / scale)²    (ν = ``grad_norm_weight``, with λ > 0)]

    w = 1 + μ · exp(−|f| / s_c)      (μ = ``contact_weight``, 0 = paper; s_c = ``contact_scale``)

(w̄ the batch mean of w: near-contact samples, where the collision label is decided, count more;
the gradient terms average over the samples whose label gradient is non-zero).
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass, fields

import torch

from ..errors import InputError
from ..models.graphdistnet.config import LOSS_KEYS


@dataclass(frozen=True)
class GraphDistNetLoss:
    """Weights of GraphDistNet's loss (module docstring).

    Attributes:
        grad_weight: λ of the gradient loss λ · (1 − cos(∂d̂/∂q, ∂f/∂q)) (0: the paper).
        grad_norm_weight: ν of the slope loss ν · ((|∂d̂/∂q| − |∂f/∂q|) / scale)²
            (needs ``grad_weight`` > 0; the cosine leaves the slope free).
        contact_weight: μ, extra weight of samples near contact in the distance loss,
            w = 1 + μ · exp(−|f| / contact_scale) (0: the paper, every sample alike).
        contact_scale: distance (m) over which the contact weight decays.
    """

    grad_weight: float = 0.0
    grad_norm_weight: float = 0.0
    contact_weight: float = 0.0
    contact_scale: float = 0.02

    def __post_init__(self) -> None:
        for f in fields(self):
            value = getattr(self, f.name)
            if isinstance(value, bool) or not isinstance(value, (int, float)):
                raise InputError(f"{f.name}: expected a number, got {value!r}")
            if not math.isfinite(value):
                raise InputError(f"{f.name}: expected finite numbers, got {value!r}")
        if self.grad_weight < 0:
            raise InputError(f"grad_weight: expected a weight ≥ 0, got {self.grad_weight}")
        if self.grad_norm_weight < 0 or (self.grad_norm_weight > 0 and self.grad_weight <= 0):
            raise InputError("grad_norm_weight must be ≥ 0, and needs grad_weight > 0")
        if self.contact_weight < 0 or self.contact_scale <= 0:
            raise InputError("contact_weight must be ≥ 0 and contact_scale positive")

    def to_dict(self) -> dict:
        return asdict(self)

    @classmethod
    def from_dict(cls, data: dict) -> GraphDistNetLoss:
        """The loss weights among ``data`` (other keys, e.g. the architecture, are ignored)."""
        return cls(**{k: data[k] for k in LOSS_KEYS if k in data})


def distance_loss(
    d_hat: torch.Tensor, d: torch.Tensor, loss: GraphDistNetLoss, scale: float
) -> torch.Tensor:
    """Σ w ((d̂ − f) / scale)² / Σ w over a batch (B,) of predictions d̂ and labels f (m)."""
    err = ((d_hat - d) / scale).square()
    if loss.contact_weight == 0:
        return err.mean()
    w = 1 + loss.contact_weight * torch.exp(-d.abs() / loss.contact_scale)
    return (w * err).sum() / w.sum()


def gradient_loss(
    g_hat: torch.Tensor, g: torch.Tensor, loss: GraphDistNetLoss, scale: float
) -> torch.Tensor:
    """λ · mean(1 − cos(ĝ, g)) + ν · mean(((|ĝ| − |g|) / scale)²) over the samples of a batch
    with a non-zero label gradient: ĝ = ∂d̂/∂q, g = ∂f/∂q (B, dof) (m/rad)."""
    norm = g.norm(dim=1)
    ok = (norm > 1e-9).float()
    cos = torch.nn.functional.cosine_similarity(g_hat, g, dim=1, eps=1e-9)
    per_sample = loss.grad_weight * (1 - cos)
    if loss.grad_norm_weight > 0:
        slope = (g_hat.norm(dim=1) - norm) / scale
        per_sample = per_sample + loss.grad_norm_weight * slope.square()
    return (per_sample * ok).sum() / ok.sum().clamp_min(1)
