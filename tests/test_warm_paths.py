"""Warm paths stay fast: a command imports only what it uses (no other command's module), a workbook is read
once, units need no pint.

The guards of the warm paths: ``mountwb run`` on
a JSON case (or the reference mount) loads neither pandas nor pint,
matplotlib, openpyxl, scikit-fem, meshio or gmsh, and on a case workbook
with its report not pandas; their tables, printed without pandas, are
pandas' own text; the factors of the unit table are
pint's to the last bit; the writer adds its sheets to the workbook the
reader opened.
"""
from __future__ import annotations

import contextlib
import io
import json
import os
import random
import subprocess
import sys
from pathlib import Path

import pandas as pd
import pytest

from workbook.answers.text_table import text_table
from workbook.model import units

ROOT = Path(__file__).resolve().parents[1]

#: Packages ``mountwb run`` on a JSON case with cached links has no use for. SciPy's own package is
#: imported (Exudyn's FEM module checks that SciPy is installed, 15 ms); its subpackages are not.
NOT_NEEDED = ("pandas", "pint", "matplotlib", "openpyxl", "skfem", "meshio", "gmsh", "dask", "pyarrow",
              "scipy.linalg", "scipy.sparse")

_PROBE = """
import sys
from workbook.cli.main import main
code = main(sys.argv[1:])
print("MODULES " + " ".join(sorted(m for m in {not_needed!r} if m in sys.modules)))
sys.exit(code)
"""


def _run(args: list[str], cache: Path) -> tuple[str, list[str]]:
    """Run ``mountwb ARGS`` in a new process: its output and the unneeded packages it imported."""
    env = dict(os.environ, MOUNTWB_CACHE=str(cache), PYTHONPATH=str(ROOT), OPENBLAS_NUM_THREADS="1")
    done = subprocess.run([sys.executable, "-c", _PROBE.format(not_needed=NOT_NEEDED), *args], env=env,
                          capture_output=True, text=True, timeout=600, cwd=ROOT)
    assert done.returncode == 0, done.stderr
    out, _, modules = done.stdout.rpartition("MODULES")
    return out, modules.split()


@pytest.mark.slow  # the links are reduced first (an empty cache)
def test_run_of_a_rigid_case_imports_only_what_it_uses(tmp_path):
    out, imported = _run(["run", "--rigid", "--no-progress"], tmp_path / "cache")
    assert "pylon isolation efficiency" in out
    assert imported == []


@pytest.mark.slow  # the links are reduced first, unless an earlier test of the session did
def test_a_workbook_run_with_its_report_imports_no_pandas(tmp_path, cache_dir):
    """``mountwb run CASE.xlsx --report R.xlsx`` prints and writes its tables without pandas; matplotlib is the
    picture process's."""
    case = tmp_path / "reference.xlsx"
    case.write_bytes((ROOT / "cases" / "reference.xlsx").read_bytes())
    out, imported = _run(["run", str(case), "--report", str(tmp_path / "report.xlsx"), "--no-progress"], cache_dir)
    assert "Pylon isolation efficiency" in out and (tmp_path / "report.xlsx").exists()
    assert [name for name in imported if name in ("pandas", "pyarrow", "matplotlib")] == []


def test_help_the_cache_listing_and_a_workbook_check_load_no_numerics(tmp_path):
    """Every command's parser is built for ``--help``: none of them may load SciPy or Exudyn to do it;
    nor does checking a case workbook (the template's with its empty Optimise sheet), which builds its case and
    runs nothing."""
    for args in (["--help"], ["run", "--help"], ["cache", "info"], ["check", str(ROOT / "cases" / "reference.xlsx")],
                 ["check", str(ROOT / "templates" / "case-template.xlsx")]):
        env = dict(os.environ, MOUNTWB_CACHE=str(tmp_path / "cache"), PYTHONPATH=str(ROOT))
        probe = ("import sys\nfrom workbook.cli.main import main\ntry:\n    main(sys.argv[1:])\nexcept SystemExit:\n"
                 "    pass\nprint('MODULES', *sorted(m for m in ('scipy', 'exudyn') if m in sys.modules))")
        done = subprocess.run([sys.executable, "-c", probe, *args], env=env, capture_output=True, text=True, timeout=120)
        assert done.returncode == 0, done.stderr
        assert done.stdout.rpartition("MODULES")[2].split() == [], args


def test_a_command_imports_the_module_of_no_other_command(tmp_path):
    """``mountwb cache info`` builds its own parser only: no other command's module is imported; without a
    command every parser is built, each with its handler."""
    from workbook.cli.main import COMMANDS, build_parser

    env = dict(os.environ, MOUNTWB_CACHE=str(tmp_path / "cache"), PYTHONPATH=str(ROOT))
    probe = ("import sys\nfrom workbook.cli.main import main\nmain(['cache', 'info'])\n"
             "print('MODULES', *sorted(m for m in sys.modules if m.startswith('workbook.cli.')))")
    done = subprocess.run([sys.executable, "-c", probe], env=env, capture_output=True, text=True, timeout=120)
    assert done.returncode == 0, done.stderr
    assert done.stdout.rpartition("MODULES")[2].split() == ["workbook.cli.cache", "workbook.cli.main"]

    def help_text(parser, name):
        text = io.StringIO()
        with contextlib.redirect_stdout(text), pytest.raises(SystemExit):
            parser.parse_args([name, "--help"])
        return text.getvalue()

    every, run_only = build_parser(), build_parser("run")
    for name in COMMANDS:
        same = help_text(every, name) == help_text(run_only, name)
        assert same == (name == "run"), name      # the other commands' arguments are added only to the full parser


@pytest.mark.slow  # the links are reduced first (an empty cache)
def test_warm_run_of_a_json_case_imports_only_what_it_uses(tmp_path):
    from workbook.model.codec import to_json
    from workbook.model.reference import reference_case

    case = tmp_path / "coarse.json"
    case.write_text(to_json(reference_case(element_size=0.03)), encoding="utf-8")
    cache = tmp_path / "cache"
    _run(["run", str(case), "--no-progress"], cache)            # reduces the links (scikit-fem is needed then)
    out, imported = _run(["run", str(case), "--json", "--no-progress"], cache)
    assert json.loads(out)["runs"]
    assert imported == []


def test_printed_tables_are_pandas_text():
    """:func:`text_table` gives what ``DataFrame.to_string(float_format=...)`` gives."""
    generator = random.Random(25)
    formats = [lambda v: f"{v:8.2f}", lambda v: f"{v:.3g}", lambda v: f"{v:10.4f}"]
    for _ in range(300):
        columns = generator.sample(["frequency Hz", "eta % x", "eta % y", "dB z", "T", "N"], generator.randint(1, 5))
        scale = generator.choice([1e-3, 1, 100, 1e4, 1e7])
        rows = {f"{generator.choice(['LP rotor', 'HP', 'a longer run name', 'x'])} {i}":
                [generator.uniform(-1, 1) * scale for _ in columns] for i in range(generator.randint(1, 5))}
        float_format = generator.choice(formats)
        frame = pd.DataFrame.from_dict(rows, orient="index", columns=columns).rename_axis("run")
        assert text_table("run", rows, columns, float_format) == frame.to_string(float_format=float_format)


def test_the_printed_summary_of_a_workbook_is_pandas_text():
    """The efficiency table ``mountwb run CASE.xlsx`` prints is the text of pandas' pivot table of it."""
    from workbook.cli.workbooks import _summary_text
    from workbook.excel.writer import ResultTable

    generator = random.Random(7)
    for _ in range(100):
        rows = []
        for run in generator.sample(["LP rotor", "HP rotor", "sweep", "a run of a longer name"], generator.randint(1, 3)):
            points = generator.randint(1, 4)
            for i in range(points):
                frequency = generator.choice([5.0, 59.0, 248.5, 5.930071, 1234.5678])
                name = run if points == 1 else f"{run} @ {frequency:g} Hz {i}"
                for direction in "xyz":
                    eta = generator.uniform(-1, 1) * generator.choice([1, 100, 1e4, 1e6])
                    missing = direction == "y" and len(rows) > 3 and generator.random() < 0.3   # pandas: NaN
                    rows.append((run, name, frequency, direction, float("nan") if missing else eta))
        table = ResultTable(("run", "point", "frequency Hz", "direction", "eta %"), rows)
        frame = pd.DataFrame(rows, columns=list(table.columns))
        frame["frequency Hz"] = frame["frequency Hz"].map("{:.6g}".format)
        pivot = frame.pivot_table(index=["run", "point", "frequency Hz"], columns="direction", values="eta %",
                                  sort=False)
        assert _summary_text(table) == pivot.to_string(float_format=lambda v: f"{v:8.2f}")


def test_tables_pandas_lays_out_by_its_own_rules_are_left_to_it():
    assert text_table("run", {"a": [float("nan")]}, ["T"], str) is None
    assert text_table("run", {"x" * 60: [1.0]}, ["T"], str) is None


def test_known_unit_factors_are_pints():
    for (text, si_unit), factor in units._KNOWN.items():
        assert units._pint_factor(text, si_unit) == factor, (text, si_unit)
    for si_unit in units._SI_UNITS:
        assert units._pint_factor(si_unit, si_unit) == 1.0, si_unit


def test_a_sheet_in_known_units_builds_no_registry():
    units.registry.cache_clear()
    units.si_factor.cache_clear()
    try:
        assert units.si_factor(" kN/mm ", "N/m") == 1e6
        assert units.si_factor("kg*m^2", "kg*m^2") == 1.0
        assert units.registry.cache_info().currsize == 0
        assert units.si_factor("lbf", "N") == pytest.approx(4.4482216152605)   # an unusual unit: pint
    finally:
        units.si_factor.cache_clear()


def test_the_writer_takes_the_workbook_the_reader_opened(tmp_path, monkeypatch):
    """The case workbook is loaded once: the writer adds its sheets to the reader's workbook."""
    import workbook.excel.writer as writer
    from workbook.excel.reader import read_workbook
    from workbook.excel.sheets import OpenedWorkbook, open_workbook

    path = tmp_path / "reference.xlsx"
    path.write_bytes((ROOT / "cases" / "reference.xlsx").read_bytes())
    book = read_workbook(path)
    assert isinstance(book.opened, OpenedWorkbook)
    loads = []
    monkeypatch.setattr(writer, "open_workbook", lambda *a, **k: loads.append(a) or open_workbook(*a, **k))
    pair = book.opened.take(book.sha256)
    assert pair is not None and book.opened.take(book.sha256) is None      # handed on once
    assert OpenedWorkbook("0" * 64, *pair).take(book.sha256) is None       # not for other bytes
    assert loads == []


def _picture_runs():
    """Runs as the report takes them: two single runs and a sweep (the answers made up)."""
    from types import SimpleNamespace

    import numpy as np

    from workbook.answers.results import MountResult

    def point(name, frequency, t):
        t = np.asarray(t, dtype=float)
        return SimpleNamespace(name=name, frequency_hz=frequency, transmissibility=t, efficiency=100 * (1 - t),
                               has_histories=False)

    def run(name, points):
        return SimpleNamespace(spec=SimpleNamespace(name=name), result=MountResult("made-up mount", points))

    sweep = [point(f"sweep @ {f:g} Hz", f, [0.5 / f, 2 / f, 1 / f]) for f in np.geomspace(5, 300, 12)]
    return [run("LP rotor", [point("LP rotor", 59.0, [0.03, 0.001, 0.02])]),
            run("HP rotor", [point("HP rotor", 248.5, [0.001, 0.002, 0.009])]), run("sweep", sweep)]


def test_pictures_drawn_in_a_second_process_are_those_drawn_here():
    from workbook.excel.pictures import draw_pictures, start_pictures

    runs = _picture_runs()
    pictures = start_pictures()
    for run in runs:
        pictures.add(run)
    try:
        drawn = pictures.result()
    finally:
        pictures.close()
    here = draw_pictures(runs)
    assert len(here) == 3 and all(png.startswith(b"\x89PNG") for png in here)
    assert drawn == here


def test_a_picture_process_never_given_runs_is_stopped():
    from workbook.excel.pictures import start_pictures

    pictures = start_pictures()
    process = pictures._process
    pictures.close()
    assert process is None or not process.is_alive()


def test_pictures_not_taken_stop_their_process():
    from workbook.excel.pictures import start_pictures

    pictures = start_pictures()
    for run in _picture_runs():
        pictures.add(run)
    process = pictures._process
    pictures.close()
    assert process is None or not process.is_alive()
    assert pictures.result()        # drawn here once the process is gone
