"""Building blocks of GraphDistNet: the MLPs h_k and the head, the masked softmax of the
readout, and the ring messages of the lean path with their hand-written backward."""

from __future__ import annotations

import itertools
import math

import torch
from torch import nn

LEAKY_SLOPE = 0.2  # negative slope of the paper's LeakyReLU


def _activation() -> nn.Module:
    return nn.LeakyReLU(LEAKY_SLOPE)


def mlp(sizes: list[int]) -> nn.Sequential:
    """Linear layers of ``sizes`` with LeakyReLU between them (none after the last)."""
    mods: list[nn.Module] = []
    for i, (a, b) in enumerate(itertools.pairwise(sizes)):
        mods.append(nn.Linear(a, b))
        if i < len(sizes) - 2:
            mods.append(_activation())
    return nn.Sequential(*mods)


def masked_softmax(logits: torch.Tensor, mask: torch.Tensor, dim: int = -1) -> torch.Tensor:
    """Softmax over ``dim`` with masked-out entries at zero weight."""
    return torch.softmax(logits.masked_fill(~mask, -math.inf), dim)


class _LeakyRingMessages(torch.autograd.Function):
    """Σ_e g(pre_e) (B, N, H) over the edges e = (prev, next, self) of every node, in place.

    pre_prev/next = u_j − u_i + c_i, pre_self = c_i and g = σ ∘ L_m ∘ σ ∘ … ∘ L_1 ∘ σ with
    σ = LeakyReLU(0.2) and the hidden linear layers L_l = (W_l, b_l) of h_k. The activations
    are applied in place and kept (σ(s) > 0 ⇔ s > 0), and the backward pass reuses its
    buffers: ∂/∂s = σ'(s) ⊙ ∂/∂σ(s), ∂/∂a = (∂/∂s) W. Gradients flow to u and c only
    (inference: the weights get none).
    """

    @staticmethod
    def forward(ctx, u: torch.Tensor, c: torch.Tensor, ring: torch.Tensor, *weights: torch.Tensor):
        b, n, hd = u.shape
        pre = u.new_empty(b, 3, n, hd)
        torch.add(u.index_select(1, ring).view(b, 2, n, hd), (c - u)[:, None], out=pre[:, :2])
        pre[:, 2] = c
        acts = [nn.functional.leaky_relu_(pre, LEAKY_SLOPE)]
        for w, bias in zip(weights[::2], weights[1::2], strict=True):
            # a product then an in-place bias: linear's addmm first copies the broadcast bias
            # into its (B·3·N, H) output (docs/decisions.md#lean-path)
            acts.append(nn.functional.leaky_relu_((acts[-1] @ w.T).add_(bias), LEAKY_SLOPE))
        ctx.save_for_backward(ring, *weights[::2], *acts)
        return acts[-1].sum(1)

    @staticmethod
    def backward(ctx, grad: torch.Tensor):
        ring, *saved = ctx.saved_tensors
        n_lin = len(saved) // 2
        ws, acts = saved[:n_lin], saved[n_lin:]
        g = torch.ops.aten.leaky_relu_backward(
            grad[:, None].expand_as(acts[-1]), acts[-1], LEAKY_SLOPE, True
        )
        for w, a in zip(reversed(ws), reversed(acts[:-1]), strict=True):
            g = g @ w
            torch.ops.aten.leaky_relu_backward.grad_input(g, a, LEAKY_SLOPE, True, grad_input=g)
        b, _, n, hd = g.shape
        ring_grad = g[:, :2]
        u_grad = (-ring_grad.sum(1)).index_add_(1, ring, ring_grad.reshape(b, 2 * n, hd))
        return (u_grad, g.sum(1), None, *(None for _ in range(2 * n_lin)))
