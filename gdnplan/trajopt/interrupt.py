"""Ctrl-C during an Ipopt solve: stop the solve at its next iteration and raise
KeyboardInterrupt after it.

A SIGINT arriving while CasADi runs Ipopt would otherwise be lost: Python raises
KeyboardInterrupt inside the next Python callback (the distance rows), CasADi turns it into a
failed evaluation, and Ipopt carries on (a shorter step) or ends with NonIpopt_Exception_Thrown,
which the planner took for one more failed seed. :func:`interruptible` replaces Python's SIGINT
handler for the length of one solve by one that only records the signal; the solver's
iteration callback (:class:`StopOnInterrupt`, CasADi's ``iteration_callback``, run once per
Ipopt iteration) then asks Ipopt to stop (status User_Requested_Stop), and
:func:`interruptible` raises KeyboardInterrupt once the solve has returned. One Ipopt
iteration of a gdnplan problem takes milliseconds; the options that could make one take
minutes (huge ``bound_push``) are refused by :func:`gdnplan.limits.check_ipopt`.
"""

from __future__ import annotations

import signal
import threading
from collections.abc import Iterator
from contextlib import contextmanager

import casadi


class _Flag:
    """Whether a SIGINT arrived during the current solve."""

    raised = False


INTERRUPT = _Flag()


class StopOnInterrupt(casadi.Callback):
    """CasADi iteration callback (inputs: the outputs of an ``nlpsol``): returns 1, which makes
    Ipopt stop with User_Requested_Stop, once a SIGINT has arrived."""

    def __init__(self, n_x: int, n_g: int) -> None:
        casadi.Callback.__init__(self)
        self.sizes = {"x": n_x, "lam_x": n_x, "g": n_g, "lam_g": n_g, "f": 1}
        self.construct("stop_on_interrupt", {})

    def get_n_in(self) -> int:
        return casadi.nlpsol_n_out()

    def get_n_out(self) -> int:
        return 1

    def get_name_in(self, i: int) -> str:
        return casadi.nlpsol_out(i)

    def get_name_out(self, i: int) -> str:
        return "stop"

    def get_sparsity_in(self, i: int) -> casadi.Sparsity:
        n = self.sizes.get(casadi.nlpsol_out(i))
        return casadi.Sparsity.dense(n) if n is not None else casadi.Sparsity(0, 0)

    def eval(self, arg) -> list:
        return [casadi.DM(1 if INTERRUPT.raised else 0)]


def _record(signum, frame) -> None:
    INTERRUPT.raised = True


@contextmanager
def interruptible() -> Iterator[None]:
    """Run one solve with SIGINT recorded instead of raised (module docstring); raise
    KeyboardInterrupt after it when one arrived. Outside the main thread, or when SIGINT does
    not raise KeyboardInterrupt (a caller's own handler), it changes nothing."""
    main = threading.current_thread() is threading.main_thread()
    if not main or signal.getsignal(signal.SIGINT) is not signal.default_int_handler:
        yield
        return
    INTERRUPT.raised = False
    signal.signal(signal.SIGINT, _record)
    try:
        yield
    finally:
        signal.signal(signal.SIGINT, signal.default_int_handler)
    if INTERRUPT.raised:
        INTERRUPT.raised = False
        raise KeyboardInterrupt


__all__ = ["INTERRUPT", "StopOnInterrupt", "interruptible"]
