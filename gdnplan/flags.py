"""The one check of an on/off setting (a flag), shared by every function and config of gdnplan.

A flag is True or False: a Python ``bool`` or a numpy bool (``np.True_``, an element of a
boolean array, what a numpy comparison returns), given back as a Python ``bool`` so that a
config stays JSON-serialisable. Nothing else is a flag: not 0 or 1 (an integer passed for a
flag is a mistake, e.g. a count in the wrong place), not a string ("no" and "false" are true
to Python), not None unless the setting allows it (``optional``: None then means "decide
for me"). A refusal is an :class:`~gdnplan.errors.InputError` naming the setting.
"""

from __future__ import annotations

import numpy as np

from .errors import InputError
from .limits import shown


def check_flag(
    value: object, name: str, optional: bool = False, lowercase: bool = False
) -> bool | None:
    """``value`` as a Python bool when it is a bool or a numpy bool (None when it is None and
    ``optional``), else InputError "name: expected True or False, got …".

    Args:
        value: the setting.
        name: its name in the message.
        optional: None is allowed (and returned).
        lowercase: spell the message ``true or false``, as TOML and JSON files do (problem
            files, weights cards).
    """
    if value is None and optional:
        return None
    if isinstance(value, (bool, np.bool_)):
        return bool(value)
    words = "true or false" if lowercase else "True or False"
    allowed = f"{words.replace(' or ', ', ')} or None" if optional else words
    raise InputError(f"{name}: expected {allowed}, got {shown(value)}")


__all__ = ["check_flag"]
