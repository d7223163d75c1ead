"""Regenerate the stress-stiffening tables in docs/flexible-links.md.

The reference mount (links at their default mesh) under the LP rotor (59 Hz)
in the frequency domain, once with ``stress_stiffening`` off and once with
the default ``auto``: each flexible link's axial preload, its first
pinned-pinned frequency unloaded and loaded, its buckling load, the thrust
rods' own bending modes in the mount, and T per direction. Replaces the
generated sections of ``docs/flexible-links.md`` (between the
``<!-- generated: ... -->`` markers); ``tests/test_docs_current.py`` checks
every section but the measured stage times (:data:`TIMED`). Run from
anywhere::

    OPENBLAS_NUM_THREADS=1 python docs/make_stiffening_docs.py
"""
from __future__ import annotations

import dataclasses
import time
from pathlib import Path

from generated_sections import rewrite_sections

from flexbodies.geometric_stiffness import link_stiffening
from workbook.model.reference import LP_ROTOR, reference_case
from workbook.solve.pipeline import prepare
from workbook.solve.stress_stiffening import AUTO_SHIFT

DOCS = Path(__file__).resolve().parent
DOCUMENT = "flexible-links.md"
#: The section of wall times: measured, so it differs from run to run.
TIMED = "stress stiffening cost"


def _prepared(case, setting):
    """Stiffening record, the lowest modes of the thrust rods in the mount (Hz), T and the stage time."""
    effects = dataclasses.replace(case.effects, stress_stiffening=setting)
    prepared = prepare(dataclasses.replace(case, effects=effects), LP_ROTOR)
    with prepared.scene:
        rods = [m.frequency_hz for m in prepared.modes
                if m.body_shares.get("thrust-left", 0) + m.body_shares.get("thrust-right", 0) > 0.95]
        t = prepared.model.result(LP_ROTOR, case.analysis.steady_tolerance).transmissibility
    return prepared.preload.stiffening, rods, t, prepared.timings["stress stiffening"]


def sections() -> dict[str, str]:
    """Every generated section of docs/flexible-links.md, by name (:data:`TIMED` holds wall times)."""
    case = dataclasses.replace(reference_case(), excitations=(LP_ROTOR,))
    _, plain_rods, plain_t, _ = _prepared(case, "off")
    models = {link.model.key(): link.model for link in case.links}
    start = time.perf_counter()
    for model in models.values():
        link_stiffening(model, use_cache=False)
    cold = time.perf_counter() - start
    record, rods, t, warm = _prepared(case, "auto")

    links = "\n".join(
        ["| link | axial preload (kN) | f1 pinned-pinned, unloaded (Hz) | loaded (Hz) | shift | buckling load (kN) "
         "| compression / buckling load (negative: tension) | stiffened by `auto` |", "|---|---|---|---|---|---|---|---|"] + [
            f"| {link.name} | {link.tension / 1e3:+.2f} | {link.unloaded_hz:.2f} | {link.loaded_hz:.2f} | "
            f"{100 * link.shift:+.2f} % | {link.buckling_load / 1e3:.4g} | {link.load_ratio:+.4f} | "
            f"{'yes' if link.stiffened else 'no'} |" for link in record.links])
    mount = "\n".join(
        ["| quantity | off | auto | change |", "|---|---|---|---|"]
        + [f"| thrust-rod bending mode {i + 1} in the mount (Hz) | {a:.2f} | {b:.2f} | {100 * (b / a - 1):+.2f} % |"
           for i, (a, b) in enumerate(zip(plain_rods[:4], rods[:4], strict=True))]
        + [f"| LP T_{axis} | {a:.5f} | {b:.5f} | {100 * (b / a - 1):+.2f} % |"
           for axis, a, b in zip("xyz", plain_t, t, strict=True)]
        + [f"| preload passes after stiffening | - | {record.passes} | last change of the tensions "
           f"{record.tension_change:.0e} |"])
    cost = (f"The stress-stiffening stage took {warm:.2f} s in this run; the geometric stiffness of the "
            f"{len(models)} distinct link models was computed once in {cold:.1f} s, then cached (wall times of "
            f"one run of the script, not checked by the tests).")
    return {"stress stiffening links": links, "stress stiffening mount": mount, TIMED: cost}


def main() -> None:
    path = rewrite_sections(DOCS / DOCUMENT, sections())
    print(f"wrote the stress-stiffening tables of {path} (auto threshold {100 * AUTO_SHIFT:g} %)")


if __name__ == "__main__":
    main()
