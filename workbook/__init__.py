"""Engine mount vibration isolation: cases, Exudyn scenes, answers and workbooks.

The public API is what ``import workbook as wb`` gives (the names of
``__all__``), the errors of :mod:`workbook.errors`, and the package
:mod:`flexbodies`; every other module is internal and may change. A script
reads::

    import workbook as wb

    result = wb.run_case(wb.reference_case())
    print(result.to_pandas())

Each name is imported on first use (PEP 562), so ``import workbook`` is
fast and a name's heavy dependencies (Exudyn, scikit-fem, openpyxl) load
only when it is used.
"""
from workbook._lazy import lazy_names

__version__ = "0.1.0"

#: Where each public name lives: its module, under the package.
_HOMES = {
    "model.case": ("Case", "Engine", "Link", "Hinge", "PointForce", "PointMoment", "Gravity", "StaticLoad",
                   "RotatingForce", "HarmonicForce", "Sweep", "RunUp", "Imbalance", "ImbalancePlane", "Rotor",
                   "Simultaneous", "AnalysisSettings", "Effects", "ForceTransducers", "DIRECTIONS"),
    "model.reference": ("reference_case", "reference_sweep", "reference_casing", "LP_ROTOR", "HP_ROTOR"),
    "model.casing": ("EngineCasing",),
    "model.pylon": ("PylonModel",),
    "model.pylon_impedance": ("PylonImpedance", "read_impedance_csv"),
    "model.pylon_beam": ("BoxBeamPylon",),
    "model.pylon_mesh": ("MeshPylon",),
    "model.codec": ("to_json", "from_json", "to_dict", "from_dict"),
    "model.drawing": ("plot_layout",),
    "solve.pipeline": ("run_case", "run_excitation", "prepare", "PreparedScene", "four_pole"),
    "solve.sweep": ("run_sweep", "SweepAnswer"),
    "solve.run_up": ("run_up", "RunUpAnswer"),
    "solve.four_pole": ("FourPole", "frequency_grid"),
    "solve.modes": ("mounted_modes", "Mode"),
    "solve.campbell": ("campbell", "CampbellDiagram"),
    "design.linear_mount": ("LinearMount", "DesignAnswer"),
    "design.sensitivity": ("DesignSensitivity", "design_sensitivity"),
    "design.optimise": ("optimise", "pareto", "OptimisationResult", "ParetoFront"),
    "answers.results": ("MountResult", "ExcitationResult"),
    "answers.isolation": ("transmissibility", "efficiency", "level_db"),
    "excel.reader": ("read_workbook", "CaseBook"),
    "excel.writer": ("write_results", "RunResult"),
    "excel.report": ("write_report",),
    "excel.template": ("template_workbook", "reference_workbook"),
    "rig.records": ("RigRecord", "read_record", "write_record"),
    "studies.parametric": ("PARAMETERS", "grid", "latin_hypercube", "study_cases"),
    "studies.parallel": ("run_rows", "RowOutcome"),
    "errors": ("MountwbError", "InputError", "CaseError", "WorkbookError", "RecordError", "UsageError", "SimulationError", "MechanismError",
               "EquilibriumError", "ResonanceError", "RoundOffError", "FourPoleError", "UnstablePreloadError", "BucklingError",
               "OutsideDesignModel", "InfeasibleProblem", "Terminated"),
}
__getattr__, __dir__, _NAMES = lazy_names(__name__, _HOMES)
__all__ = ["__version__", *_NAMES]
