"""``mountwb cache {info,verify,clear} [--folder DIR]``: the store of reduced bodies (links, casing, mesh pylon)
and of the links' geometric stiffness.

``info`` lists the folder, its entries and their size (a folder that does
not exist holds nothing; a file of its name is a usage error); ``verify`` checks
every entry's key and checksum and names each corrupt one (exit 1 when
there is one; a run would recompute and replace it anyway); ``clear``
removes every entry, lock file and temporary file of the store, and
nothing else.
"""
from __future__ import annotations

import argparse
from typing import Callable

from workbook.errors import UsageError

__all__ = ["arguments"]


def arguments(parser: argparse.ArgumentParser) -> Callable:
    parser.add_argument("action", choices=("info", "verify", "clear"),
                        help="info: list the entries; verify: check every key and checksum; clear: remove the entries")
    parser.add_argument("--folder", help="cache folder (default: $MOUNTWB_CACHE, else ~/.cache/mountwb)")
    return cache


def _size(total: int) -> str:
    return f"{total / 1e6:.1f} MB"


def cache(args) -> int:
    from flexbodies.cache import BodyCache

    store = BodyCache(args.folder)
    if store.folder.exists() and not store.folder.is_dir():
        named = f"--folder {store.folder}" if args.folder else f"{store.folder} ($MOUNTWB_CACHE)"
        raise UsageError(f"{named}: a file; expected the cache folder")
    if not store.folder.exists():
        print(f"{store.folder}: no such folder, nothing stored")
        return 0
    if args.action == "clear":
        print(f"{store.folder}: removed {store.clear()} file(s)")
        return 0
    if args.action == "info":
        entries = store.entries()
        summaries = sum(1 for path in entries if path.suffix == ".json")
        clamped = sum(1 for path in entries if path.name.startswith("clamped-"))
        stiffening = len(store.stiffening_files())
        total = sum(path.stat().st_size for path in entries)
        print(f"{store.folder}: {len(entries) - summaries - clamped - stiffening} reduced body(ies), {clamped} clamped "
              f"reduction(s), {summaries} frequency summary(ies), {stiffening} geometric stiffness file(s), "
              f"{_size(total)}")
        for path in store.stale_temporaries():
            print(f"  stale temporary file (the next run removes it): {path.name}")
        return 0
    reports = store.verify()
    bad = [report for report in reports if report.problem is not None]
    for report in bad:
        print(f"corrupt: {report.problem}")
    print(f"{store.folder}: {len(reports)} entries checked, {len(bad)} corrupt"
          + (" (a run recomputes and replaces them; 'mountwb cache clear' removes everything)" if bad else ""))
    return 1 if bad else 0
