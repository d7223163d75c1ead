"""``mountwb links [CASE] [--export FOLDER] [--verify ...]``: the links as reduced for a case.

Per link: FE DOF, first frequencies free-free and as mounted, the ratio of
every excitation of the case to the mounted fundamental, the
fixed-interface modes kept and why, the reduction time and the cache hit;
``--export`` writes each link in Exudyn's own reduced-body format.
``--verify`` compares each distinct link design's reduced models with its
full FE model against the number of fixed-interface modes
(:mod:`flexbodies.verification`): a table, ``--plot`` and ``--json``.
"""
from __future__ import annotations

import argparse
import contextlib
import json
import sys
from pathlib import Path
from typing import Callable

from workbook.cli.loading import load_case
from workbook.cli.outputs import check_output, output_folder, write_output
from workbook.errors import UsageError

__all__ = ["arguments"]


def arguments(parser: argparse.ArgumentParser) -> Callable:
    parser.add_argument("case", nargs="?", help="case file (JSON or .xlsx workbook); default: the reference mount")
    parser.add_argument("--export", type=output_folder, metavar="FOLDER",
                        help="also write each reduced link in Exudyn's own format (FOLDER/<link>.npz; an existing "
                             "file is kept: a new name)")
    parser.add_argument("--verify", action="store_true",
                        help="compare each distinct link design's reduced models with its full FE model (clamped "
                             "at eye A, 1e5 N at eye B): static and harmonic tip response and the first frequencies "
                             "against the fixed-interface modes kept")
    parser.add_argument("--modes", default="0,2,6,12,20", metavar="0,2,6,12,20",
                        help="--verify: fixed-interface mode counts (0,2,6,12,20)")
    parser.add_argument("--frequencies", default="1000,10000,20000", metavar="HZ,HZ",
                        help="--verify: excitation frequencies of the harmonic load case, Hz (1000,10000,20000)")
    parser.add_argument("--basis", choices=("cb", "orthonormal"), default="cb",
                        help="--verify: the package's Craig-Bampton basis, or it orthonormalised and truncated as "
                             "a modal neutral file is (cb)")
    parser.add_argument("--plot", metavar="OUT.png", help="--verify: write frequencies and response error against "
                                                          "modes kept as PNG")
    parser.add_argument("--json", action="store_true", help="--verify: print the verification as JSON")
    return links


def _numbers(text: str, option: str, kind=float) -> tuple:
    try:
        values = tuple(kind(part) for part in text.split(","))
    except ValueError:
        raise UsageError(f"{option} {text!r}: expected {'whole ' if kind is int else ''}numbers separated by ','") \
            from None
    if any(not value >= 0 for value in values) or (kind is float and any(value <= 0 for value in values)):
        raise UsageError(f"{option} {text!r}: expected {'counts >= 0' if kind is int else 'frequencies > 0 Hz'}")
    return values


def _verify(args, case) -> int:
    from flexbodies.craig_bampton import MODE_BUDGET
    from flexbodies.verification import VerificationSet, verify_link_model
    from workbook.answers.saving import save_figure

    modes = _numbers(args.modes, "--modes", int)
    if max(modes) > MODE_BUDGET:
        raise UsageError(f"--modes {args.modes!r}: at most {MODE_BUDGET} fixed-interface modes")
    frequencies = _numbers(args.frequencies, "--frequencies")
    designs: dict = {}
    for link in case.links:
        designs.setdefault(link.model, []).append(link.name)
    items = tuple(verify_link_model(model, names[0], modes=modes, frequencies_hz=frequencies, basis=args.basis)
                  for model, names in designs.items())
    result = VerificationSet(items)
    figure = result.plot() if args.plot else None
    if args.json:
        print(json.dumps(result.to_json(), indent=1))
    else:
        print(f"{case.name}: reduced links against their full FE models, clamped at eye A, "
              f"{items[0].force:g} N along the link axis at eye B ({args.basis} basis)\n")
        formats = {c: "{:.3e}".format for c in result.to_pandas().columns if c.endswith("[m]")}
        formats.update({c: "{:+.3g}".format for c in result.to_pandas().columns if c.endswith("[%]")})
        formats.update({c: "{:.0f}".format for c in result.to_pandas().columns if c.endswith("[Hz]")})
        formats["wall time [s]"] = "{:.3g}".format
        for item, names in zip(items, designs.values(), strict=True):
            table = item.to_pandas().droplevel("link").drop(columns="modes")
            shown = [c for c in table.columns if not c.startswith("tip at")]
            print(f"{item.name} ({', '.join(names)}; {item.description}); the reduced rows share "
                  f"{item.shared_seconds:.2f} s of factorisation and fixed-interface modes")
            print(table[shown].to_string(formatters={c: formats[c] for c in shown if c in formats}))
            print()
        for text in dict.fromkeys(item.explanation() for item in items):
            print(text)
    with contextlib.redirect_stdout(sys.stderr) if args.json else contextlib.nullcontext():
        if figure is not None:
            write_output(args.plot, "plot", "links", lambda target: save_figure(figure, target, dpi=110))
    return 0


def _exporter(link) -> Callable[[Path], Path]:
    """The writer of *link*'s file in Exudyn's own reduced-body format."""
    from flexbodies import export_exudyn_file

    def write(target: Path) -> Path:
        return export_exudyn_file(link, target)

    return write


def links(args) -> int:
    from workbook.answers.link_table import link_table
    from workbook.scene.build import reduce_links

    check_output("--plot", args.plot, (".png",), [args.case])
    if not args.verify:
        given = [option for option, value in (("--plot", args.plot), ("--json", args.json),
                                              ("--basis", args.basis != "cb"), ("--modes", args.modes != "0,2,6,12,20"),
                                              ("--frequencies", args.frequencies != "1000,10000,20000")) if value]
        if given:
            raise UsageError(f"{given[0]} belongs to --verify: add --verify")
    case = load_case(args.case)
    if args.verify:
        return _verify(args, case)
    reduced = reduce_links(case)
    table = link_table(case, reduced)
    print(f"{case.name}: links as reduced for the highest excitation of the case\n")
    formats = {"f1 free-free [Hz]": "{:.0f}", "f1 mounted [Hz]": "{:.0f}", "reduction [s]": "{:.2f}"}
    formats.update({c: "{:.3f}" for c in table.columns if c.startswith("f_exc/f1")})
    if len(case.excitations) > 1:
        table = table.drop(columns="f_exc/f1")  # the highest excitation's column is among the per-excitation ones
    print(table.drop(columns="why").to_string(formatters={k: f.format for k, f in formats.items()}))
    print()
    for name, reason in table["why"].items():
        print(f"{name}: {reason}")
    if args.export:
        for name, link in reduced.items():
            write_output(str(Path(args.export) / f"{name}.npz"), f"link {name}", "export", _exporter(link))
    return 0
