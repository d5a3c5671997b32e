"""JSON that other tools can read: non-finite numbers become null, never NaN."""

from __future__ import annotations

import json
import math

import numpy as np


def _floats(a: np.ndarray):
    """A float array as nested lists with non-finite entries as None (vectorised)."""
    if np.all(np.isfinite(a)):
        return a.tolist()
    return np.where(np.isfinite(a), a, None).tolist()


def clean(obj):
    """A copy of ``obj`` with NumPy scalars and arrays as plain Python, NaN/inf as None."""
    if isinstance(obj, dict):
        return {str(k): clean(v) for k, v in obj.items()}
    if isinstance(obj, list | tuple):
        if obj and all(type(v) is float for v in obj):  # the common case: a row of floats
            return _floats(np.asarray(obj, dtype=float))
        return [clean(v) for v in obj]
    if isinstance(obj, np.ndarray):
        if obj.dtype.kind in "fiub":
            return _floats(obj.astype(float)) if obj.dtype.kind == "f" else obj.tolist()
        return clean(obj.tolist())
    if isinstance(obj, np.generic):
        obj = obj.item()
    if isinstance(obj, float) and not math.isfinite(obj):
        return None
    return obj


def dumps(obj, **kwargs) -> str:
    return json.dumps(clean(obj), allow_nan=False, **kwargs)
