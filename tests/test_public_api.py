"""The public API: what ``import workbook as wb`` gives, and which modules are public.

As SciPy's test of its public API: every module of the two packages is
either public (listed in ``PUBLIC_MODULES``) or internal (listed in
``INTERNAL_MODULES``); a new module fails here until it is put in one list,
so nothing becomes public by accident.
"""
from __future__ import annotations

import importlib
import importlib.metadata
import inspect
import pkgutil
import subprocess
import sys

import pytest

import flexbodies
import workbook

#: Modules a user may import; their names are the API.
PUBLIC_MODULES = ("workbook", "workbook.errors", "flexbodies", "flexbodies.errors")

#: Modules of the implementation: importable, but their names may change between versions.
INTERNAL_MODULES = (
    "workbook.design", "workbook.design.assembly", "workbook.design.blocks", "workbook.design.channel_set",
    "workbook.design.equilibrium", "workbook.design.expansion", "workbook.design.harmonic_model",
    "workbook.design.pinned_shift", "workbook.design.memory",
    "workbook.design.kinematics", "workbook.design.sensitivity",
    "workbook.design.linear_mount", "workbook.design.optimise", "workbook.design.bands", "workbook.design.link_fatigue",
    "workbook.design.link_margins", "workbook.design.section_search",
    "workbook.answers", "workbook.answers.amplitude", "workbook.answers.hinge_curves", "workbook.answers.isolation",
    "workbook.answers.link_stiffness",
    "workbook.answers.link_table", "workbook.answers.model_card", "workbook.answers.results",
    "workbook.answers.saving", "workbook.answers.text_table", "workbook.answers.warning_groups",
    "workbook.cli", "workbook.cli.cache", "workbook.cli.campbell", "workbook.cli.four_pole", "workbook.cli.layout",
    "workbook.cli.links", "workbook.cli.loading", "workbook.cli.loads", "workbook.cli.main", "workbook.cli.outputs",
    "workbook.cli.stress", "workbook.cli.optimise",
    "workbook.cli.params", "workbook.cli.uq",
    "workbook.cli.rig", "workbook.cli.run", "workbook.cli.run_up", "workbook.cli.study", "workbook.cli.workbooks",
    "workbook.excel", "workbook.excel.execute", "workbook.excel.files", "workbook.excel.impedance_sheet",
    "workbook.excel.layout", "workbook.excel.loads_sheet", "workbook.excel.optimise_sheet",
    "workbook.excel.fatigue_sheet", "workbook.excel.pictures", "workbook.excel.reader", "workbook.excel.report",
    "workbook.excel.rig_points",
    "workbook.excel.runs", "workbook.excel.sheets", "workbook.excel.styling", "workbook.excel.template",
    "workbook.excel.writer",
    "workbook.model", "workbook.model.case", "workbook.model.casing", "workbook.model.codec",
    "workbook.model.drawing", "workbook.model.field_spec", "workbook.model.fields", "workbook.model.load_cases", "workbook.model.pylon",
    "workbook.model.pylon_beam", "workbook.model.pylon_legacy", "workbook.model.pylon_impedance",
    "workbook.model.spectrum",
    "workbook.model.pylon_mesh", "workbook.model.reference", "workbook.model.units",
    "workbook.processes",
    "workbook.rig", "workbook.rig.channel_map", "workbook.rig.correlation", "workbook.rig.plots", "workbook.rig.records",
    "workbook.rig.synthetic", "workbook.rig.uff", "workbook.rig.frf", "workbook.rig.modal", "workbook.rig.updating",
    "workbook.cli.update",
    "workbook.scene", "workbook.scene.bearing", "workbook.scene.build", "workbook.scene.engine_casing",
    "workbook.scene.excitation", "workbook.scene.hinge_law", "workbook.scene.hinge_law_base",
    "workbook.scene.hinge_laws", "workbook.scene.link_workers",
    "workbook.scene.mode_budget", "workbook.scene.structural_damping",
    "workbook.solve", "workbook.solve.campbell", "workbook.solve.flexible_pylon", "workbook.solve.four_pole",
    "workbook.solve.bore_convergence", "workbook.solve.bore_fatigue", "workbook.solve.fatigue",
    "workbook.solve.guards", "workbook.solve.harmonic", "workbook.solve.load_cases", "workbook.solve.method", "workbook.solve.modes",
    "workbook.solve.pipeline", "workbook.solve.preload",
    "workbook.solve.response_sweep", "workbook.solve.run_up",
    "workbook.solve.simultaneous", "workbook.solve.stages", "workbook.solve.steady_start",
    "workbook.solve.step_accuracy", "workbook.solve.stress_stiffening", "workbook.solve.sweep",
    "workbook.solve.sweep_grid", "workbook.solve.time_domain", "workbook.solve.truncation",
    "workbook.studies", "workbook.studies.accuracy", "workbook.studies.parallel", "workbook.studies.parametric",
    "workbook.studies.progress", "workbook.studies.sensitivity", "workbook.studies.uncertainty",
    "flexbodies.assembly", "flexbodies.atomic", "flexbodies.bore_stress", "flexbodies.bores", "flexbodies.cache", "flexbodies.cached_reduction",
    "flexbodies.casing", "flexbodies.casing_reduction", "flexbodies.craig_bampton", "flexbodies.eigen",
    "flexbodies.exudyn_body", "flexbodies.frequencies", "flexbodies.geometric_stiffness", "flexbodies.geometry",
    "flexbodies.interfaces", "flexbodies.interior", "flexbodies.invariants", "flexbodies.link",
    "flexbodies.materials", "flexbodies.meshing", "flexbodies.pylon_reduction", "flexbodies.reduced", "flexbodies.reduction",
    "flexbodies.selection", "flexbodies.stress", "flexbodies.validation", "flexbodies.verification",
)


def _modules() -> list[str]:
    found = []
    for package in (workbook, flexbodies):
        found.append(package.__name__)
        found += [module.name for module in pkgutil.walk_packages(package.__path__, f"{package.__name__}.")]
    return found


def test_every_module_is_either_public_or_internal():
    modules = _modules()
    unlisted = [m for m in modules if m not in PUBLIC_MODULES + INTERNAL_MODULES and "._" not in m]
    assert not unlisted, (f"new module(s) {unlisted}: add each to PUBLIC_MODULES (its names become API) or to "
                          f"INTERNAL_MODULES in this file, or give it a leading underscore")
    gone = [m for m in PUBLIC_MODULES + INTERNAL_MODULES if m not in modules]
    assert not gone, f"listed module(s) {gone} no longer exist: take them off the lists"


@pytest.mark.parametrize("package", [workbook, flexbodies], ids=lambda p: p.__name__)
def test_every_public_name_resolves_to_its_home_object(package):
    for name in package.__all__:
        value = getattr(package, name)
        assert name in dir(package)
        if name.startswith("__"):
            continue
        home = getattr(value, "__module__", None)
        if inspect.isclass(value) or inspect.isfunction(value):
            assert getattr(importlib.import_module(home), value.__name__) is value
            assert inspect.getdoc(value), f"{package.__name__}.{name} has no docstring"


def test_an_unknown_name_is_an_attribute_error():
    with pytest.raises(AttributeError, match="has no attribute 'run_cases'"):
        workbook.run_cases  # noqa: B018


def test_the_version_is_the_installed_distributions():
    assert workbook.__version__ == importlib.metadata.version("engine-mount-workbook")


@pytest.mark.parametrize("package, heavy", [
    ("workbook", ("exudyn", "skfem", "gmsh", "scipy", "pandas", "openpyxl", "matplotlib")),
    ("flexbodies", ("exudyn", "skfem", "gmsh", "pandas", "openpyxl", "matplotlib")),  # SciPy: Craig-Bampton's own
])
def test_importing_a_package_loads_none_of_the_heavy_dependencies(package, heavy):
    code = f"import sys, {package}; print(sorted(m for m in {heavy!r} if m in sys.modules))"
    loaded = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout.strip()
    assert loaded == "[]"


@pytest.mark.parametrize("module, old, new", [
    ("flexbodies", "ReducedLink", "ReducedBody"), ("flexbodies", "LinkMesh", "BodyMesh"),
    ("flexbodies", "ReducedLinkFileError", "ReducedBodyFileError"), ("flexbodies", "load_reduced_link", "load_reduced_body"),
    ("flexbodies", "save_reduced_link", "save_reduced_body"), ("flexbodies.reduced", "ReducedLink", "ReducedBody"),
    ("flexbodies.cache", "LinkCache", "BodyCache"), ("flexbodies.meshing", "LinkMesh", "BodyMesh"),
    ("flexbodies.errors", "ReducedLinkFileError", "ReducedBodyFileError"),
])
def test_a_former_name_of_the_general_machinery_warns_and_is_the_new_one(module, old, new):
    namespace = importlib.import_module(module)
    with pytest.warns(DeprecationWarning, match=f"{module}.{old} is now {module}.{new}; {old} goes in version 0.3"):
        value = getattr(namespace, old)
    assert value is getattr(namespace, new)
    assert old not in getattr(namespace, "__all__", ())


def test_a_former_method_of_the_cache_warns_and_calls_the_new_one(tmp_path):
    from flexbodies.cache import BodyCache

    store = BodyCache(tmp_path)
    with pytest.warns(DeprecationWarning, match=r"BodyCache.load_link\(\) is now load_body\(\)"):
        assert store.load_link("absent") is None
    with pytest.warns(DeprecationWarning, match=r"BodyCache.link_path\(\) is now body_path\(\)"):
        assert store.link_path("k") == store.body_path("k")
