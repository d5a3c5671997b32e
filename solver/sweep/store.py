"""The resumable sweep store: a manifest and one file per finished point, each written
atomically (temporary file, then rename), so that nothing computed is lost and a torn
file cannot exist."""

from __future__ import annotations

import json
import os
from pathlib import Path

from .._json import dumps
from .points import SweepPoint

__all__ = [
    "STORE_FORMAT",
    "SweepStoreError",
    "open_store",
    "point_text",
    "store_point",
    "write_atomic",
]

STORE_FORMAT = 1


class SweepStoreError(ValueError):
    """A sweep folder that cannot be resumed (another model, or another sweep)."""


def write_atomic(path: Path, text: str) -> None:
    """Write ``text`` to ``path`` through a temporary file and a rename."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    tmp = path.with_name(f".{path.name}.{os.getpid()}.tmp")
    try:
        tmp.write_text(text, encoding="utf-8")
        os.replace(tmp, path)
    finally:
        tmp.unlink(missing_ok=True)


def point_text(point: SweepPoint) -> str:
    """``dumps(point.to_dict())``: the point's JSON, with NaN written as null."""
    d = point.to_dict()
    try:
        # A point's dict is plain Python but for NumPy floats (floats to json) and the odd
        # NaN; the cleaning walk (a third of the time) is needed only then.
        return json.dumps(d, allow_nan=False)
    except (TypeError, ValueError):
        return dumps(d)


def store_point(store: Path, index: int, point: SweepPoint) -> str:
    """Write one finished point atomically; return its text."""
    text = point_text(point)
    write_atomic(Path(store) / "points" / f"{index:05d}.json", text)
    return text


def open_store(
    store: Path, manifest: dict, texts: dict[int, str] | None = None
) -> dict[int, SweepPoint]:
    """Create the store, or check that it holds this very sweep; return its points (and
    put their texts into ``texts``)."""
    store = Path(store)
    store.mkdir(parents=True, exist_ok=True)
    path = store / "manifest.json"
    if path.exists():
        old = json.loads(path.read_text(encoding="utf-8"))
        if old.get("model_hash") != manifest["model_hash"]:
            raise SweepStoreError(
                f"{store} was written by another model version (hash "
                f"{str(old.get('model_hash'))[:12]}, this model {manifest['model_hash'][:12]}); "
                "choose another output folder or delete it"
            )
        differs = [k for k in manifest if old.get(k) != manifest[k]]
        if differs:
            raise SweepStoreError(
                f"{store} holds another sweep ({', '.join(differs)} differ); choose another "
                "output folder or delete it"
            )
    else:
        write_atomic(path, dumps(manifest, indent=1))
    done = {}
    for f in sorted((store / "points").glob("[0-9]*.json")):
        try:
            text = f.read_text(encoding="utf-8")
            data = json.loads(text)
        except (ValueError, OSError):
            f.unlink(missing_ok=True)  # a torn file cannot exist (atomic writes); be safe
            continue
        try:
            done[int(f.stem)] = SweepPoint.from_dict(data)
            if texts is not None:
                texts[int(f.stem)] = text
        except (KeyError, TypeError, ValueError):
            raise SweepStoreError(
                f"{f} is not a sweep point this version reads; choose another output folder "
                "or delete it"
            ) from None
    return done
