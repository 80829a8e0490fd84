"""``friction_uq.run`` and ``friction_uq.campaign``: a function of the Python interface and a subpackage at once.

Once a subpackage is imported, Python binds its name on the package to the module, shadowing the
interface's function of the same name (:mod:`friction_uq.api`). :func:`make_callable` makes the module
callable as that function, so ``friction_uq.run(path)`` works whichever was loaded first. The
function is looked up when called, not when the subpackage loads: the subpackages sit below the
interface and do not import it.
"""

from __future__ import annotations

import importlib
import inspect
import sys
import types
from typing import Any


def _function(name: str):
    return getattr(importlib.import_module("friction_uq.api"), name)


def make_callable(module_name: str, func_name: str) -> None:
    """Make the subpackage ``module_name`` callable as ``friction_uq.api.<func_name>``."""
    mod = sys.modules[module_name]

    class CallableModule(types.ModuleType):
        def __call__(self, *args: Any, **kwargs: Any) -> Any:
            return _function(func_name)(*args, **kwargs)

        @property
        def __signature__(self) -> inspect.Signature:  # help() and inspect show the function's parameters
            return inspect.signature(_function(func_name))

    mod.__class__ = CallableModule
