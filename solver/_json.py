"""JSON that other tools can read: non-finite numbers become null, never NaN."""

from __future__ import annotations

import json
import math

import numpy as np


def clean(obj):
    """A copy of ``obj`` with NumPy scalars and arrays as plain Python, NaN/inf as None."""
    if isinstance(obj, dict):
        return {str(k): clean(v) for k, v in obj.items()}
    if isinstance(obj, list | tuple):
        return [clean(v) for v in obj]
    if isinstance(obj, np.ndarray):
        return clean(obj.tolist())
    if isinstance(obj, np.generic):
        obj = obj.item()
    if isinstance(obj, float) and not math.isfinite(obj):
        return None
    return obj


def dumps(obj, **kwargs) -> str:
    return json.dumps(clean(obj), allow_nan=False, **kwargs)
