"""The resumable sweep store: a manifest and one file per finished point, each written
atomically (temporary file, then rename), so that nothing computed is lost and a torn
file cannot exist."""

from __future__ import annotations

import json
import os
from pathlib import Path

from .._json import dumps
from .points import SweepPoint

__all__ = ["STORE_FORMAT", "SweepStoreError", "open_store", "store_point"]

STORE_FORMAT = 1


class SweepStoreError(ValueError):
    """A sweep folder that cannot be resumed (another model, or another sweep)."""


def store_point(store: Path, index: int, point: SweepPoint) -> None:
    """Write one finished point atomically."""
    folder = Path(store) / "points"
    folder.mkdir(parents=True, exist_ok=True)
    path = folder / f"{index:05d}.json"
    tmp = folder / f".{index:05d}.json.{os.getpid()}.tmp"
    tmp.write_text(dumps(point.to_dict()), encoding="utf-8")
    os.replace(tmp, path)


def open_store(store: Path, manifest: dict) -> dict[int, SweepPoint]:
    """Create the store, or check that it holds this very sweep; return its points."""
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
        tmp = store / ".manifest.json.tmp"
        tmp.write_text(dumps(manifest, indent=1), encoding="utf-8")
        os.replace(tmp, path)
    done = {}
    for f in sorted((store / "points").glob("[0-9]*.json")):
        try:
            data = json.loads(f.read_text(encoding="utf-8"))
        except (ValueError, OSError):
            f.unlink(missing_ok=True)  # a torn file cannot exist (atomic writes); be safe
            continue
        try:
            done[int(f.stem)] = SweepPoint.from_dict(data)
        except (KeyError, TypeError, ValueError):
            raise SweepStoreError(
                f"{f} is not a sweep point this version reads; choose another output folder "
                "or delete it"
            ) from None
    return done
