"""Registries of named robots and scenes, and where their built-in entries are defined.

:func:`gdnplan.robot.load_robot` and :func:`gdnplan.scene.make_scene` look names up here. A
factory registers itself when its module is imported (``@register_robot``,
``@register_scene``). Most built-in factories live in modules above the registries' users —
:mod:`gdnplan.planar` builds its arms with :mod:`gdnplan.urdf_robot`, :mod:`gdnplan.ur5e` needs
coal distances for the fetch scene — so a registry never imports them: the package declares
them (``gdnplan/__init__.py`` calls :meth:`Registry.declare`) as a name → the module that
registers it. A lookup of a declared name imports that module; listing the names imports every
declared module. ``import gdnplan`` thus builds no robot and imports no pinocchio model.
"""

from __future__ import annotations

import importlib
import inspect
from collections.abc import Callable

from .errors import InputError, UnknownNameError, did_you_mean


class Registry:
    """Named factories of one kind (``"robot"``, ``"scene"``), filled by :meth:`register`."""

    def __init__(self, kind: str):
        self.kind = kind
        self.factories: dict[str, Callable] = {}
        self.builtins: dict[str, str] = {}  # declared name -> module that registers it

    def register(self, name: str) -> Callable:
        """Decorator registering a factory under ``name``."""

        def wrap(factory: Callable) -> Callable:
            self.factories[name] = factory
            return factory

        return wrap

    def declare(self, modules: dict[str, str]) -> None:
        """Declare built-in names: name → the module (``"gdnplan.ur5e"``) registering it."""
        self.builtins.update(modules)

    def __contains__(self, name: object) -> bool:
        """True for a registered or declared name (imports nothing)."""
        return name in self.factories or name in self.builtins

    def names(self) -> list[str]:
        """Every registered name, sorted (imports the declared modules first)."""
        for module in dict.fromkeys(self.builtins.values()):
            importlib.import_module(module)
        return sorted(self.factories)

    def get(self, name: str) -> Callable:
        """The factory of ``name``; UnknownNameError listing the names when there is none."""
        if not isinstance(name, str):  # a list is no dictionary key (TypeError)
            raise UnknownNameError(
                f"{self.kind}: expected a name, got {type(name).__name__}; choose one of "
                f"{self.names()}"
            )
        if name not in self.factories and name in self.builtins:
            importlib.import_module(self.builtins[name])
        if name not in self.factories:
            raise UnknownNameError(
                f"{self.kind}: unknown name {name!r}{did_you_mean(name, self.names())}; "
                f"choose one of {self.names()}"
            )
        return self.factories[name]

    def build(self, name: str, fixed: tuple[str, ...] = (), **options):
        """``factory(**options)`` of ``name``, after checking the option names: one the factory
        does not take is an InputError naming it and the ones it takes (Python's TypeError
        "unexpected keyword argument" before); ``fixed`` names options the caller always
        passes (``seed``), not listed as choices."""
        factory = self.get(name)
        allowed = options_of(factory) - set(fixed)
        unknown = sorted(set(options) - allowed - set(fixed))
        if unknown:
            takes = f"it takes {sorted(allowed)}" if allowed else "it takes none"
            raise InputError(
                f"{self.kind} {name!r}: unknown option(s) {unknown}"
                f"{did_you_mean(unknown[0], allowed)}; {takes}"
            )
        return factory(**options)


def options_of(factory: Callable) -> set[str]:
    """Names of the parameters of ``factory`` that can be given by keyword."""
    kinds = (inspect.Parameter.POSITIONAL_OR_KEYWORD, inspect.Parameter.KEYWORD_ONLY)
    return {p.name for p in inspect.signature(factory).parameters.values() if p.kind in kinds}


ROBOTS = Registry("robot")
SCENES = Registry("scene")
