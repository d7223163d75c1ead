"""One root for every error the package raises on purpose.

Every error class of :mod:`workbook.errors` and :mod:`flexbodies.errors`
derives from :class:`workbook.errors.MountwbError` and carries its exit
code; the command line reports bad input (exit 2) only for those and for a
file that cannot be read, and any other exception as an internal error
(exit 1) with its traceback in a log file; a static check keeps plain
``raise ValueError(...)`` out of the modules that check the user's input.
"""
import ast
import inspect
import json
import os
import subprocess
import sys
from pathlib import Path

import pytest

import flexbodies.errors
import workbook.errors
from workbook.cli.main import main
from workbook.errors import EXIT_BAD_INPUT, EXIT_FAILED_ROWS, EXIT_TROUBLE, InputError, MountwbError, SimulationError, Terminated, exit_code
from workbook.model.codec import to_dict
from workbook.model.reference import reference_case

ROOT = Path(__file__).resolve().parents[1]

#: Exception classes raised as built-in ones; the checks below look for these.
PLAIN = {"ValueError", "TypeError", "RuntimeError", "KeyError", "IndexError", "LookupError", "ArithmeticError",
         "AssertionError", "NotImplementedError", "Exception"}

#: The raises that stay plain, by module and function, and why: each is a defect of the package or of a
#: program calling it, never the user's case, workbook, record, mesh or command line.
PLAIN_RAISES = {
    ("workbook/design/kinematics.py", "identify"): "a marker of the scene the package built (caught: OutsideDesignModel)",
    # internal invariants: the package made the value that fails
    ("workbook/answers/amplitude.py", "period_window"): "histories the package computed (rig records are checked first)",
    ("workbook/answers/amplitude.py", "_uniform_step"): "histories the package computed (rig records are checked first)",
    ("workbook/answers/isolation.py", "pylon_sum"): "a mount without pylon-side hinges is refused earlier as a mechanism",
    ("workbook/excel/layout.py", "Column.__post_init__"): "the package's own column table",
    ("workbook/excel/layout.py", "Table.column"): "the package's own column table",
    ("workbook/model/field_spec.py", "field_spec"): "a field the package's own column table names",
    ("workbook/model/field_spec.py", "documented"): "a case dataclass of the package without its field specs",
    ("workbook/scene/structural_damping.py", "equivalent_viscous_damping"): "frequencies the case checks are > 0",
    ("workbook/solve/preload.py", "applied_static_force"): "bodies of the scene the package built",
    ("workbook/studies/parallel.py", "_run_processes"): "a value the study runner sets",
    ("flexbodies/cache.py", "read_summary_file"): "caught at once and raised as ReducedBodyFileError",
    ("flexbodies/geometric_stiffness.py", "stiffened"): "two results of the package that must agree",
    ("flexbodies/interior.py", "InteriorSolver.__init__"): "coordinates the package ordered",
    # arguments of a Python function that only calling code gives (the command line never passes a bad one)
    ("workbook/answers/results.py", "MountResult.run"): "a run name asked for in Python",
    ("workbook/answers/results.py", "MountResult._table_rows"): "a quantity asked for in Python (MountResult.to_pandas, to_text)",
    ("workbook/answers/text_table.py", "text_table"): "rows and columns the package built",
    ("workbook/answers/results.py", "MountResult.plot_time_histories"): "a plot asked for in Python",
    ("workbook/solve/four_pole.py", "FourPole.direction_values"): "a quantity asked for in Python",
    ("workbook/studies/accuracy.py", "run_study"): "a ladder given in Python",
    ("workbook/studies/sensitivity.py", "table_path"): "a format the command line restricts to its choices",
    ("flexbodies/craig_bampton.py", "craig_bampton"): "an argument pair given in Python",
    ("flexbodies/meshing.py", "BodyMesh.__post_init__"): "a mesh object of the wrong type given in Python",
    ("flexbodies/validation.py", "harmonic_response_check"): "a direction asked for in Python",
}

#: Exception classes that stay outside the root: SIGTERM unwinds like Ctrl-C, and a cell reader's
#: private signal is caught in its module and reported as a workbook problem.
OUTSIDE_ROOT = {("workbook/errors.py", "Terminated"), ("workbook/excel/sheets.py", "_Bad")}


def _exported_errors(module):
    return [value for name in module.__all__ if inspect.isclass(value := getattr(module, name))
            and issubclass(value, BaseException)]


@pytest.mark.parametrize("cls", [c for c in _exported_errors(workbook.errors) + _exported_errors(flexbodies.errors)
                                 if c is not Terminated], ids=lambda c: c.__name__)
def test_every_error_class_derives_from_the_root_and_has_an_exit_code(cls):
    assert issubclass(cls, MountwbError)
    assert cls.exit_code in (EXIT_TROUBLE, EXIT_BAD_INPUT, EXIT_FAILED_ROWS)
    if cls is not MountwbError:  # the root itself is never raised
        assert cls.exit_code == (EXIT_TROUBLE if issubclass(cls, SimulationError) else EXIT_BAD_INPUT)
        # callers that catch ValueError (bad input) or RuntimeError (numerical trouble) still catch them
        assert issubclass(cls, RuntimeError if issubclass(cls, SimulationError) else ValueError)


def test_flexbodies_errors_are_bad_input_and_the_package_names_them():
    import flexbodies

    for cls in _exported_errors(flexbodies.errors):
        assert issubclass(cls, InputError)
        assert getattr(flexbodies, cls.__name__) is cls
    with pytest.raises(flexbodies.LinkModelError, match="unknown material 'unobtainium'"):
        flexbodies.material("unobtainium")


def test_exit_code_follows_the_root():
    assert exit_code(workbook.errors.UsageError("bad option")) == EXIT_BAD_INPUT
    assert exit_code(flexbodies.errors.LinkModelError("bad bore")) == EXIT_BAD_INPUT
    assert exit_code(workbook.errors.DivergenceError("diverged")) == EXIT_TROUBLE
    assert exit_code(FileNotFoundError(2, "No such file or directory", "case.json")) == EXIT_BAD_INPUT
    # any other exception is a defect of the package, never bad input
    assert exit_code(ValueError("a bug")) == EXIT_TROUBLE
    assert exit_code(ZeroDivisionError("a bug")) == EXIT_TROUBLE


def test_workbook_errors_imports_nothing_of_the_package():
    """flexbodies.errors imports workbook.errors: the reverse would be a cycle."""
    tree = ast.parse((ROOT / "workbook" / "errors.py").read_text(encoding="utf-8"))
    imported = {alias.name for node in ast.walk(tree) if isinstance(node, ast.Import) for alias in node.names}
    imported |= {node.module or "" for node in ast.walk(tree) if isinstance(node, ast.ImportFrom)}
    assert not {name for name in imported if name.split(".")[0] in ("workbook", "flexbodies")}
    tree = ast.parse((ROOT / "flexbodies" / "errors.py").read_text(encoding="utf-8"))
    imported = {node.module for node in ast.walk(tree) if isinstance(node, ast.ImportFrom)}
    assert imported <= {"__future__", "workbook.errors", "workbook._renamed"}  # _renamed imports no module of the package


def _sources():
    for package in ("workbook", "flexbodies"):
        for path in sorted((ROOT / package).rglob("*.py")):
            yield path.relative_to(ROOT).as_posix(), ast.parse(path.read_text(encoding="utf-8"))


def _scoped(tree):
    """(qualified scope, node) of every node below *tree*."""
    def visit(node, scope):
        for child in ast.iter_child_nodes(node):
            inner = scope + [child.name] if isinstance(child, (ast.FunctionDef, ast.AsyncFunctionDef,
                                                                 ast.ClassDef)) else scope
            yield ".".join(inner), child
            yield from visit(child, inner)
    yield from visit(tree, [])


def test_no_plain_raise_outside_the_known_defects():
    """A plain ``raise ValueError(...)`` (or TypeError, RuntimeError, KeyError, ...) reads as a defect
    of the package on the command line: bad input raises an error of the root instead."""
    found = set()
    for path, tree in _sources():
        for scope, node in _scoped(tree):
            if isinstance(node, ast.Raise) and node.exc is not None:
                raised = node.exc.func if isinstance(node.exc, ast.Call) else node.exc
                if isinstance(raised, ast.Name) and raised.id in PLAIN:
                    found.add((path, scope))
                    assert (path, scope) in PLAIN_RAISES, (
                        f"{path}:{node.lineno} ({scope}) raises a plain {raised.id}: raise an error of "
                        f"workbook.errors or flexbodies.errors for bad input, or list it in PLAIN_RAISES if it is "
                        f"a defect of the package")
    assert found == set(PLAIN_RAISES), f"listed but gone: {sorted(set(PLAIN_RAISES) - found)}"


def test_every_error_class_of_the_package_is_under_the_root():
    """No module defines an exception class of its own outside the root."""
    rooted = {c.__name__ for c in _exported_errors(workbook.errors) + _exported_errors(flexbodies.errors)
              if issubclass(c, MountwbError)}
    for path, tree in _sources():
        for _, node in _scoped(tree):
            if isinstance(node, ast.ClassDef) and (path, node.name) not in OUTSIDE_ROOT | {("workbook/errors.py",
                                                                                            "MountwbError")}:
                bases = {base.id for base in node.bases if isinstance(base, ast.Name)}
                assert bases & rooted or not bases & (PLAIN | {"OSError", "KeyboardInterrupt", "BaseException"}), (
                    f"{path}: class {node.name} derives from a built-in exception only; derive it from "
                    f"workbook.errors.MountwbError (or InputError, SimulationError)")


def test_a_bad_link_geometry_is_bad_input_on_the_command_line(tmp_path):
    """A real run of the command line on a case whose link bore is larger than its eye."""
    data = to_dict(reference_case())
    data["links"][0]["model"]["geometry"]["bore_radius"] = 0.05
    path = tmp_path / "bad-bore.json"
    path.write_text(json.dumps(data), encoding="utf-8")
    done = subprocess.run([sys.executable, "-m", "workbook.cli.main", "run", str(path), "--no-progress"],
                          capture_output=True, text=True, cwd=tmp_path, timeout=300,
                          env={**os.environ, "PYTHONPATH": str(ROOT)})
    assert done.returncode == EXIT_BAD_INPUT, done.stderr
    assert done.stdout == ""
    assert done.stderr.strip() == ("mountwb run: link geometry: the bore radius (0.05 m) must be smaller than the "
                                   "eye outer radius (0.038 m)")


def test_a_missing_case_file_is_named(tmp_path, capsys):
    assert main(["run", str(tmp_path / "no-such-case.json"), "--no-progress"]) == EXIT_BAD_INPUT
    err = capsys.readouterr().err
    assert "no-such-case.json: the case cannot be read (No such file or directory)" in err
    assert "internal error" not in err


@pytest.mark.parametrize("defect", [ZeroDivisionError("float division by zero"),
                                    ValueError("operands could not be broadcast together")],
                         ids=["ZeroDivisionError", "ValueError"])
def test_a_defect_of_the_package_is_an_internal_error_with_its_traceback_logged(tmp_path, monkeypatch, capsys,
                                                                                defect):
    import tempfile

    import workbook.solve.pipeline

    def broken(case, **kwargs):
        raise defect

    monkeypatch.setattr(workbook.solve.pipeline, "run_case", broken)
    monkeypatch.setattr(tempfile, "tempdir", str(tmp_path))
    assert main(["run", "--no-progress"]) == EXIT_TROUBLE
    out, err = capsys.readouterr()
    assert out == ""
    lines = err.strip().splitlines()
    assert len(lines) == 1, err
    assert lines[0].startswith(f"mountwb run: internal error (a bug of mountwb, not of your input): "
                               f"{type(defect).__name__}: {defect}; the traceback is in ")
    assert "bad input" not in err and "Traceback" not in err
    log = Path(lines[0].split("the traceback is in ")[1])
    assert log.parent == tmp_path and log.name.startswith("mountwb-internal-error-") and log.suffix == ".log"
    text = log.read_text(encoding="utf-8")
    assert text.startswith("mountwb run --no-progress\n")
    assert "Traceback (most recent call last)" in text and "in broken" in text
    assert f"{type(defect).__name__}: {defect}" in text
