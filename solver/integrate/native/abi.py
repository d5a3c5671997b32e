"""The one call into the compiled library: ``int gs_integrate(const gs_job *job)``.

:class:`Job` is the C struct ``gs_job`` of ``native_*.c``, declared here once.  The C
exports its layout (``gs_job_fields``: each field's name and kind in order;
``gs_job_layout``: the ABI version, ``sizeof(gs_job)`` and each field's ``offsetof``);
:func:`bind` compares them with this declaration when a library is loaded and refuses a
library that differs, with one line saying how.

Nothing unchecked reaches the C: :func:`fill` checks every integer against the int64
range before ctypes could wrap it, and every array's length (computed in Python's exact
integers) against the sizes it is read with; the C checks them again and returns a code
(:data:`ERRORS`) instead of writing out of bounds.
"""

from __future__ import annotations

import ctypes

import numpy as np

__all__ = ["ABI_VERSION", "ERRORS", "FLAGS", "Job", "LayoutMismatch", "bind", "call", "fill"]

ABI_VERSION = 2
INT64_MIN, INT64_MAX = -(2**63), 2**63 - 1
# gs_integrate's refusals (``GS_E_*`` of native_*.c); Python's checks come first, so one of
# these means the two sides disagree (a bug), except memory.
ERRORS = {
    -1: "the library's job layout version differs from abi.py's",
    -2: "an array's length or a size does not match the job's sizes",
    -3: "an option of the job is out of its range",
    -4: "the integrator could not allocate its work arrays (out of memory)",
    -5: "the forcing frequency must be positive at every point in the phase time mode",
}
FLAGS = {"dense": 1, "batched": 2, "period_stops": 4}

_I, _D, _P = ctypes.c_int64, ctypes.c_double, ctypes.c_void_p
_INTS = (
    "abi n_points n_states n_params group transient periods samples_per_period "
    "steps_per_period lyapunov_periods max_steps method time_mode omega_index valid_range "
    "flags"
).split()
_DOUBLES = ("t0", "period", "rtol", "atol", "bound")
# (name, dtype): the arrays, each followed in the struct by ``<name>_len`` (elements)
ARRAYS = (
    ("P", np.float64),
    ("X0", np.float64),
    ("bounds", np.float64),
    ("tangent0", np.float64),
    ("x", np.float64),
    ("xmin", np.float64),
    ("xmax", np.float64),
    ("exponent", np.float64),
    ("tangent", np.float64),
    ("nfev", np.int64),
    ("nsteps", np.int64),
    ("status", np.int32),
    ("t_fail", np.float64),
    ("exits", np.float64),
)
_KIND = {_I: "i", _D: "d", _P: "p"}


class LayoutMismatch(RuntimeError):
    """The compiled library's ``gs_job`` differs from :class:`Job`."""


class Job(ctypes.Structure):
    """``gs_job`` of ``native_*.c``: int64 sizes and options, doubles, and each array as a
    pointer with its length in elements (NULL: not given / not collected)."""

    _fields_ = [
        *((name, _I) for name in _INTS),
        *((name, _D) for name in _DOUBLES),
        *(f for name, _ in ARRAYS for f in ((name, _P), (f"{name}_len", _I))),
    ]


def _layout() -> tuple[str, list[int]]:
    names = " ".join(f"{name}:{_KIND[kind]}" for name, kind in Job._fields_) + " "
    offsets = [ABI_VERSION, ctypes.sizeof(Job), *(getattr(Job, n).offset for n, _ in Job._fields_)]
    return names, offsets


def _difference(theirs: list, ours: list, got: list, offsets: list) -> str:
    """The first difference between the C's layout and :class:`Job`'s, in words."""
    for k, (a, b) in enumerate(zip(theirs, ours, strict=False)):
        if a != b:
            return f"field {k}: C {a!r}, Python {b!r}"
    if len(theirs) != len(ours):
        return f"C {len(theirs)} fields, Python {len(ours)}"
    labels = ["version", "size", *(f"offset of {name.split(':')[0]}" for name in ours)]
    for label, a, b in zip(labels, got, offsets, strict=False):
        if a != b:
            return f"{label}: C {a}, Python {b}"
    return f"C {len(got)} layout numbers, Python {len(offsets)}"


def bind(lib: ctypes.CDLL, path: str) -> None:
    """Declare ``gs_integrate`` and the helpers on ``lib`` after checking that its
    ``gs_job`` is :class:`Job`; raises :class:`LayoutMismatch` with one line."""
    try:
        lib.gs_job_fields.restype = ctypes.c_char_p
        lib.gs_job_fields.argtypes = []
        lib.gs_job_layout.restype = _I
        lib.gs_job_layout.argtypes = [ctypes.POINTER(_I), _I]
    except AttributeError:
        raise LayoutMismatch(
            f"the compiled library {path} has no job layout (built by an older gearsym); "
            "delete it to rebuild"
        ) from None
    names, offsets = _layout()
    theirs = lib.gs_job_fields().decode()
    table = (_I * 256)()
    count = lib.gs_job_layout(table, 256)
    got = list(table[: min(count, 256)])
    if theirs != names or got != offsets:
        where = _difference(theirs.split(), names.split(), got, offsets)
        raise LayoutMismatch(
            f"the compiled library {path} lays out gs_job differently from abi.py ({where}); "
            "rebuild it (delete the cached library) or update abi.py with native_*.c"
        )
    lib.gs_integrate.restype = ctypes.c_int
    lib.gs_integrate.argtypes = [ctypes.POINTER(Job)]
    f64 = np.ctypeslib.ndpointer(np.float64, flags="C")
    lib.gs_eval.restype = None
    lib.gs_eval.argtypes = [_D, f64, f64, f64]
    lib.gs_eval_batch.restype = None
    lib.gs_eval_batch.argtypes = [_D, ctypes.c_int, f64, f64, f64]
    lib.gs_rhs_loop.restype = _D
    lib.gs_rhs_loop.argtypes = [f64, f64, ctypes.c_longlong, _D]


def _int64(name: str, value) -> int:
    if isinstance(value, bool) or not isinstance(value, (int, np.integer)):
        raise ValueError(f"{name} must be a whole number, got {value!r}")
    value = int(value)
    if not INT64_MIN <= value <= INT64_MAX:
        raise ValueError(f"{name} = {value} is outside the 64-bit integer range; lower it")
    return value


def fill(ints: dict, doubles: dict, arrays: dict, lengths: dict) -> tuple[Job, list]:
    """A :class:`Job` from its integers, doubles and arrays.

    ``arrays`` maps a name of :data:`ARRAYS` to a C-contiguous array of its dtype or None;
    ``lengths`` maps each given array's name to the element count the C reads or writes
    (exact Python integers, so a product that overflows int64 is caught here).  Returns
    the job and the arrays it points into (keep them alive during the call).
    """
    job = Job()
    for name in _INTS:
        setattr(job, name, _int64(name, ints[name]))
    for name in _DOUBLES:
        setattr(job, name, float(doubles[name]))
    keep = []
    for name, dtype in ARRAYS:
        a = arrays.get(name)
        if a is None:
            continue
        if (
            a.dtype != dtype
            or not a.flags.c_contiguous
            or (not a.flags.writeable and name not in ("P", "X0", "bounds", "tangent0"))
        ):
            raise ValueError(f"{name} must be a C-contiguous {np.dtype(dtype)} array")
        want = _int64(f"the length of {name}", lengths[name])
        if a.size != want:
            raise ValueError(f"{name} holds {a.size} numbers where the run needs {want}")
        setattr(job, name, a.ctypes.data)
        setattr(job, f"{name}_len", a.size)
        keep.append(a)
    return job, keep


def call(lib: ctypes.CDLL, job: Job) -> None:
    """Run ``gs_integrate``; a refusal raises (MemoryError for memory, else RuntimeError:
    Python's checks should have caught it first)."""
    code = lib.gs_integrate(ctypes.byref(job))
    if code == -4:
        raise MemoryError(ERRORS[code])
    if code != 0:
        raise RuntimeError(f"gs_integrate refused the job: {ERRORS.get(code, code)}")
