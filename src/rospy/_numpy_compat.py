"""numpy names that ROS 1 node code uses and that numpy has since removed.

Noetic runs on Ubuntu 20.04's numpy 1.17, where ``np.int``, ``np.float``, ``np.bool``, ``np.NaN``,
``np.float_`` and the like still exist; course and driver code of that era uses them freely (ROBOTIS'
TurtleBot3 AutoRace lane detector sizes its sliding windows with ``np.int``). numpy 1.24 removed the
builtin aliases and numpy 2 the rest, so such a node dies in its first callback here while it runs on
Noetic. When a node starts (:func:`rospy.init_node`) and its script has imported numpy, the names
numpy no longer has are put back, meaning what they meant in numpy 1.17; names numpy has are never
touched. A script that never imports numpy does not get it imported.
"""

from __future__ import annotations

import sys
import warnings
from typing import Any


def _aliases(np: Any) -> dict[str, Any]:
    """Each removed name and what numpy 1.17 gave for it."""
    return {
        # the builtin aliases (deprecated in 1.20, removed in 1.24)
        "int": int,
        "float": float,
        "complex": complex,
        "object": object,
        "bool": bool,
        "str": str,
        "long": int,
        "unicode": str,
        # removed in numpy 2.0
        "float_": np.float64,
        "complex_": np.complex128,
        "string_": np.bytes_,
        "unicode_": np.str_,
        "Inf": np.inf,
        "Infinity": np.inf,
        "infty": np.inf,
        "PINF": np.inf,
        "NINF": -np.inf,
        "NaN": np.nan,
        "PZERO": 0.0,
        "NZERO": -0.0,
        "product": np.prod,
        "cumproduct": np.cumprod,
        "alltrue": np.all,
        "sometrue": np.any,
        "round_": np.round,
    }


def restore_numpy_aliases() -> list[str]:
    """Put back the removed names on an imported numpy; the names added (none without numpy)."""
    np = sys.modules.get("numpy")
    if np is None:
        return []
    added: list[str] = []
    for name, value in _aliases(np).items():
        if name not in vars(np):
            try:
                with warnings.catch_warnings():  # numpy's "will be defined as ..." FutureWarnings
                    warnings.simplefilter("ignore")
                    getattr(np, name)
                continue  # numpy still provides it (through its module __getattr__)
            except AttributeError:
                pass
            setattr(np, name, value)
            added.append(name)
    return added
