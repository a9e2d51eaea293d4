"""Compare every number two output directories hold: a refactoring must not change results.

    python benchmarks/compare_runs.py OLD_DIR NEW_DIR [--tolerance 1e-10]

Walks the JSON files (summary, static, modes) and the HDF5 datasets (time series) of
OLD_DIR, finds the same in NEW_DIR, and reports the largest relative difference
|a - b| / max(|a|, |b|, tiny) per file.  Timings (keys ending in ``_s``) are skipped.
Exit 1 if any difference exceeds the tolerance or a number is missing.
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

import h5py
import numpy as np


def _numbers(value, prefix=""):
    """Flatten JSON into {path: number}; skips timings (``*_s``) and strings."""
    if isinstance(value, dict):
        for key, item in value.items():
            if not str(key).endswith("_s"):
                yield from _numbers(item, f"{prefix}.{key}")
    elif isinstance(value, list):
        for i, item in enumerate(value):
            yield from _numbers(item, f"{prefix}[{i}]")
    elif isinstance(value, (int, float)) and not isinstance(value, bool):
        yield prefix, float(value)


def _relative(a: np.ndarray, b: np.ndarray) -> float:
    a, b = np.asarray(a, dtype=float), np.asarray(b, dtype=float)
    if a.shape != b.shape:
        return np.inf
    both_nan = np.isnan(a) & np.isnan(b)
    scale = np.maximum(np.maximum(np.abs(a), np.abs(b)), 1e-300)
    diff = np.where(both_nan, 0.0, np.abs(a - b) / scale)
    return float(np.max(diff)) if diff.size else 0.0


def compare(old: Path, new: Path) -> dict[str, float]:
    out = {}
    for path in sorted(old.rglob("*.json")):
        a = dict(_numbers(json.loads(path.read_text())))
        b = dict(_numbers(json.loads((new / path.relative_to(old)).read_text())))
        missing = set(a) - set(b)
        worst = max((_relative(a[k], b[k]) for k in a if k in b), default=0.0)
        out[str(path.relative_to(old))] = np.inf if missing else worst
    for path in sorted(old.rglob("timeseries.h5")):
        with h5py.File(path) as fa, h5py.File(new / path.relative_to(old)) as fb:
            names = [n for n in fa if isinstance(fa[n], h5py.Dataset)]
            out[str(path.relative_to(old))] = max(
                _relative(fa[n][()], fb[n][()]) if n in fb else np.inf for n in names)
    return out


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("old", type=Path)
    parser.add_argument("new", type=Path)
    parser.add_argument("--tolerance", type=float, default=1e-10)
    args = parser.parse_args()
    results = compare(args.old, args.new)
    for name, worst in results.items():
        print(f"{name:40s} largest relative difference {worst:.3e}")
    return 0 if all(w <= args.tolerance for w in results.values()) else 1


if __name__ == "__main__":
    sys.exit(main())
