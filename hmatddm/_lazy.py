"""Lazy package attributes (PEP 562): a package names what it exports and where each
name lives; the module is imported on first access, not when the package is imported.

This keeps ``import hmatddm`` (and ``hmatddm --help``, ``hmatddm scenes``, a refused
scene) free of numba, the H-matrix engine, scipy.special, pyvista and matplotlib.
"""
import importlib
import sys
import types


def attach(package, exports, submodules=()):
    """``(__getattr__, __dir__)`` for ``package``: ``exports`` maps a public name to the
    relative module that defines it (``{"Simulation": ".simulation"}``); ``submodules``
    are names imported as modules (``hd.mesh``), or a mapping of such a name to the
    relative module it stands for (``{"topology": ".mesh.topology"}``: a module that
    lives in a room keeps its short public name)."""
    if not isinstance(submodules, dict):
        submodules = {name: "." + name for name in submodules}

    def __getattr__(name):
        if name in submodules:
            return importlib.import_module(submodules[name], package)
        if name in exports:
            value = getattr(importlib.import_module(exports[name], package), name)
            globals_of_package = importlib.import_module(package).__dict__
            globals_of_package[name] = value  # later lookups do not come back here
            return value
        raise AttributeError(f"module {package!r} has no attribute {name!r}")

    def __dir__():
        return sorted(set(importlib.import_module(package).__dict__) | set(exports) | set(submodules))

    module = sys.modules[package]
    if any(name not in submodules for name in exports):
        module.__class__ = _ExportsFirst
        module._exports_first = frozenset(exports)
    return __getattr__, __dir__


class _ExportsFirst(types.ModuleType):
    """A package whose exports win over its submodules of the same name: importing
    ``hmatddm.elasticity.solve`` (the module) must not turn ``hmatddm.elasticity.solve``
    (the function) into the module, as the import system would by binding the submodule on its parent."""

    def __setattr__(self, name, value):
        if isinstance(value, types.ModuleType) and name in self.__dict__.get("_exports_first", ()):
            return
        super().__setattr__(name, value)
