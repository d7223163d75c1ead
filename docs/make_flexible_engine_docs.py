"""Regenerate the tables of docs/flexible-engine.md.

The reference mount (links at their default mesh, the frequency domain) under
the LP (59 Hz) and HP (248.5 Hz) rotors, once with the rigid engine and once
with the reference casing (:func:`workbook.model.reference.reference_casing`):
T per direction in dB and the change, the casing's size, first free-free
mode and the modes kept for each rotor, and the cost. Replaces the generated
sections of ``docs/flexible-engine.md``; ``tests/test_docs_current.py`` checks
every section but the measured times (:data:`TIMED`). Run from anywhere::

    OPENBLAS_NUM_THREADS=1 python docs/make_flexible_engine_docs.py
"""
from __future__ import annotations

import dataclasses
import time
from pathlib import Path

from generated_sections import rewrite_sections

from workbook.answers.isolation import level_db
from workbook.model.reference import HP_ROTOR, LP_ROTOR, reference_case, reference_casing
from workbook.scene.engine_casing import reduce_engine_casing
from workbook.solve.pipeline import prepare

DOCS = Path(__file__).resolve().parent
DOCUMENT = "flexible-engine.md"
#: The section of wall times: measured, so it differs from run to run.
TIMED = "flexible engine cost"
#: A coarser mesh of the casing, for the mesh's effect on its first modes, m.
COARSER = 0.12


def _answer(case, excitation):
    """T per direction, the scene's DOF, the reduced casing (or None) and the wall time of the run, s."""
    start = time.perf_counter()
    prepared = prepare(case, excitation)
    with prepared.scene as scene:
        t = prepared.model.result(excitation, case.analysis.steady_tolerance).transmissibility
        dof = sum(scene.body_dof().values())
        reduced = scene.casing.reduced if scene.casing is not None else None
    return t, dof, reduced, time.perf_counter() - start


def sections() -> dict[str, str]:
    """Every generated section of docs/flexible-engine.md, by name (:data:`TIMED` holds wall times)."""
    rigid = reference_case()
    casing = reference_casing()
    flexible = dataclasses.replace(rigid, engine=dataclasses.replace(rigid.engine, casing=casing))
    rows, facts, costs = [], [], []
    for excitation in (LP_ROTOR, HP_ROTOR):
        _answer(rigid, excitation)                             # warm: links reduced, exudyn loaded
        t_rigid, dof_rigid, _, seconds_rigid = _answer(rigid, excitation)
        _answer(flexible, excitation)
        t_flex, dof_flex, reduced, seconds_flex = _answer(flexible, excitation)
        for axis, a, b in zip("xyz", level_db(t_rigid), level_db(t_flex), strict=True):
            rows.append(f"| {excitation.name} ({excitation.frequency:g} Hz) | T_{axis} | {a:.2f} | {b:.2f} | "
                        f"{b - a:+.2f} |")
        facts.append(f"| {excitation.name} ({excitation.frequency:g} Hz) | {dof_rigid} | {dof_flex} | "
                     f"{reduced.n_fixed_interface} | {reduced.decision.reason} |")
        costs.append((excitation, seconds_rigid, seconds_flex, reduced.info))
    coarse = dataclasses.replace(casing, element_size=COARSER, modes="static")
    coarse_hz = reduce_engine_casing(dataclasses.replace(
        rigid, engine=dataclasses.replace(rigid.engine, casing=coarse)), LP_ROTOR.frequency).frequencies["free_free_hz"]
    g = casing.geometry
    casing_facts = (f"The casing: {g.length:g} m long (x {g.x_start:g} to {g.x_end:g} m), outer radius {g.radius:g} m, "
                    f"wall {1e3 * g.thickness:g} mm, {casing.material.name} (E {casing.material.youngs_modulus / 1e9:g} "
                    f"GPa, {casing.material.density:g} kg/m^3), mount rings "
                    + ", ".join(f"at x = {r.x:g} m ({1e3 * r.width:g} mm wide, to r = {r.outer_radius:g} m)"
                                for r in g.rings)
                    + f"; {reduced.info['fe_dof']} FE DOF ({casing.element_size:g} m quadratic tetrahedra), "
                    f"{reduced.mass:.1f} kg of the engine's {rigid.engine.mass:g} kg; first free-free elastic "
                    f"modes {', '.join(f'{f:.1f}' for f in reduced.frequencies['free_free_hz'][:4])} Hz "
                    f"({', '.join(f'{f:.1f}' for f in coarse_hz[:4])} Hz with {COARSER:g} m elements). Bearings at "
                    f"x = {', '.join(f'{x:g}' for x in casing.bearing_planes)} m, "
                    f"{casing.bearing_stiffness[1]:.3g} N/m radial and axial; casing modal damping "
                    f"{casing.modal_damping:g}.")
    table = "\n".join(["| run | direction | rigid engine (dB) | flexible engine (dB) | change (dB) |",
                       "|---|---|---|---|---|"] + rows)
    sizes = "\n".join(["| run | scene DOF, rigid engine | scene DOF, flexible engine | casing fixed-interface "
                       "modes | why |", "|---|---|---|---|---|"] + facts)
    info = costs[-1][3]
    cost = ("One reduction of the casing serves both rotors (then it is cached); it took: mesh "
            f"{info['mesh_seconds']:.1f} s, assembly {info['assembly_seconds']:.1f} s, factorisation, static and "
            f"fixed-interface modes {info['reduction_seconds']:.1f} s, free-free frequencies "
            f"{info['frequency_seconds']:.1f} s. A warm run (links and casing from the cache) took "
            + "; ".join(f"{e.name} {rigid_s:.2f} s with the rigid engine, {flex_s:.2f} s with the flexible one"
                        for e, rigid_s, flex_s, _ in costs)
            + " (wall times measured on one machine, not checked by the tests).")
    return {"flexible engine casing": casing_facts, "flexible engine T": table, "flexible engine size": sizes,
            TIMED: cost}


def main() -> None:
    path = rewrite_sections(DOCS / DOCUMENT, sections())
    print(f"wrote the flexible-engine tables of {path}")


if __name__ == "__main__":
    main()
