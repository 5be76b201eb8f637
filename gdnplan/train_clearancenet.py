"""Deprecated location of ClearanceNet's training: :mod:`gdnplan.train.clearancenet`
(``from gdnplan.train import train_clearancenet``). The names stay importable from here."""

from .train.clearancenet import ClearanceNetLearner, train, train_and_save, train_and_score

__all__ = ["ClearanceNetLearner", "train", "train_and_save", "train_and_score"]
