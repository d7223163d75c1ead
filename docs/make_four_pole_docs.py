"""Regenerate the figure and the generated sections of docs/four-pole.md.

The reference mount (``workbook.model.reference.reference_case()``): its
answers on the example pylon-impedance table and on the example box-beam
pylon against the rigid pylon, a stiff pylon tending to the rigid one, its
four-pole set from 10 to 500 Hz (``docs/four-pole.png``, as
``mountwb four-pole --plot`` draws it) and at the two rotor frequencies with
the insertion loss on an example pylon, and the rigid-pylon T of the set
against the frequency-domain run. ``tests/test_docs_current.py`` regenerates
the sections and fails when the committed page differs. Run from anywhere::

    OPENBLAS_NUM_THREADS=1 python docs/make_four_pole_docs.py
"""
from __future__ import annotations

import dataclasses
from pathlib import Path

import matplotlib
import numpy as np
import scipy.linalg as sla

matplotlib.use("Agg")

from generated_sections import rewrite_sections  # noqa: E402

from flexbodies import TITANIUM  # noqa: E402
from workbook.model.pylon_beam import (
    BoxBeamPylon,  # noqa: E402
    beam_model,  # noqa: E402
)
from workbook.model.pylon_impedance import read_impedance_csv  # noqa: E402
from workbook.model.reference import HP_ROTOR, LP_ROTOR, reference_case  # noqa: E402
from workbook.solve.four_pole import REPORT_GRID, frequency_grid  # noqa: E402
from workbook.solve.harmonic import excitation_phasor  # noqa: E402
from workbook.solve.pipeline import (
    four_pole,  # noqa: E402
    run_case,  # noqa: E402
)

DOCS = Path(__file__).resolve().parent
DOCUMENT = "four-pole.md"
#: The example impedance table of the page.
IMPEDANCE_TABLE = DOCS / "pylon-impedance-example.csv"
#: The example box-beam pylon of the page (an illustration, not a pylon's data).
EXAMPLE_BEAM = BoxBeamPylon(root=(-2.6, 0.0, 1.1), tip=(0.2, 0.0, 1.1), width=0.6, height=0.8, wall=0.006,
                            material=TITANIUM, loss_factor=0.02)
#: Pylon point stiffness per pin of the insertion-loss example, N/m.
EXAMPLE_PYLON = 5e7
#: Pylon stiffnesses per pin of the convergence to the rigid pylon, N/m.
STIFF_PYLONS = (1e10, 1e12, 1e14, 1e16)
ROTORS = (LP_ROTOR, HP_ROTOR)


def _sci(value: float, digits: int) -> str:
    """*value* as ``8.991e6``: *digits* decimals, no exponent padding."""
    mantissa, exponent = f"{value:.{digits}e}".split("e")
    return f"{mantissa}e{int(exponent)}"


def _triple(values, spec: str) -> str:
    if spec.endswith("e"):
        return ", ".join(_sci(v, int(spec[1:-1])) for v in values)
    return ", ".join(f"{v:{spec}}" for v in values)


def _rows(left, right, spec: str, header: str) -> str:
    rows = [header, "|---|---|---|"]
    for rotor in ROTORS:
        rows.append(f"| {rotor.name}, {rotor.frequency_hz:g} Hz | {_triple(left(rotor), spec)} | "
                    f"{_triple(right(rotor), spec)} |")
    return "\n".join(rows)


def _set_t(pole, pylon=None) -> dict:
    """T of each rotor from the four-pole set at the rotors' frequencies (rigid pylon, or *pylon* N/m per pin)."""
    frequencies = list(pole.frequencies_hz)
    return {rotor: pole.transmissibility(excitation_phasor(rotor), rotor.point, pylon)[
        frequencies.index(rotor.frequency_hz)] for rotor in ROTORS}


def sections(figure_path: Path | None = None) -> dict[str, str]:
    """Every generated section of docs/four-pole.md, by name; the figure is written to *figure_path* if given."""
    case = reference_case()
    rigid = run_case(case)
    table = run_case(dataclasses.replace(case, pylon=read_impedance_csv(IMPEDANCE_TABLE)))
    impedance = _rows(lambda r: rigid.run(r.name).efficiency, lambda r: table.run(r.name).efficiency, ".2f",
                      "| run | eta x, y, z on the rigid pylon (%) | eta x, y, z on the example pylon (%) |")

    pole = four_pole(case, frequency_grid(LP_ROTOR.frequency_hz, HP_ROTOR.frequency_hz, 2))
    rigid_set = _set_t(pole)
    stiff = []
    for stiffness in STIFF_PYLONS:
        on_pylon = _set_t(pole, stiffness)
        stiff.append(max(float(np.max(np.abs(on_pylon[r] / rigid_set[r] - 1))) for r in ROTORS))
    convergence = (
        "As the pylon stiffens the answers tend to the rigid pylon's: on the reference mount (its four-pole set at "
        f"{' and '.join(f'{r.frequency_hz:g}' for r in ROTORS)} Hz, both rotors) the largest relative difference of "
        "T from the rigid pylon is " + ", ".join(_sci(d, 1) for d in stiff) + " for "
        + ", ".join(_sci(s, 0) for s in STIFF_PYLONS) + " N/m per pin (falling as 1 / Z_p).")

    beam = run_case(dataclasses.replace(case, pylon=EXAMPLE_BEAM))
    model = beam_model(EXAMPLE_BEAM, [position for position, _ in case.pylon_pins()])
    clamped = np.sqrt(sla.eigh(model.stiffness, model.mass, eigvals_only=True)[:3]) / (2 * np.pi)
    beam_modes = ("Its first modes alone, clamped at the root with the pins' fittings as stations: "
                  + ", ".join(f"{f:.1f}" for f in clamped) + " Hz.")
    beam_table = _rows(lambda r: rigid.run(r.name).transmissibility, lambda r: beam.run(r.name).transmissibility,
                       ".5f", "| run | T x, y, z on the rigid pylon | T x, y, z on the box beam |")

    grid = four_pole(case, frequency_grid(*REPORT_GRID))
    if figure_path is not None:
        grid.plot().savefig(figure_path, dpi=120)
    low = {q: grid.direction_values(q)[0] for q in ("K11", "K21", "K22")}
    low["K21"] = -low["K21"]
    spread = max(float(np.ptp([low[q][d].real for q in low]) / abs(low["K11"][d].real)) for d in (0, 2))
    springs = (
        f"At {grid.frequencies_hz[0]:g} Hz the mount is nearly a massless spring: K11, -K21 and K22 agree within "
        f"{100 * spread:.1f} % in x and z (real parts, N/m: x "
        + _triple([low[q][0].real for q in low], ".3e") + "; z " + _triple([low[q][2].real for q in low], ".3e")
        + ").")

    magnitudes = ["| f (Hz) | \\|K11\\| x, y, z (N/m) | \\|K21\\| x, y, z (N/m) | \\|K22\\| x, y, z (N/m) |",
                  "|---|---|---|---|"]
    values = {q: np.abs(pole.direction_values(q)) for q in ("K11", "K21", "K22")}
    for i, frequency in enumerate(pole.frequencies_hz):
        magnitudes.append(f"| {frequency:g} | " + " | ".join(_triple(values[q][i], ".3e") for q in values) + " |")
    runs = _rows(lambda r: rigid.run(r.name).transmissibility, lambda r: rigid_set[r], ".4g",
                 "| run | `run_case` (frequency domain) | four-pole set, rigid pylon |")
    difference = max(float(np.max(np.abs(rigid_set[r] / rigid.run(r.name).transmissibility - 1))) for r in ROTORS)
    agreement = (f"The set and the run differ by at most {100 * difference:.2f} % here (the set's links are "
                 f"reduced for {HP_ROTOR.frequency_hz:g} Hz, the LP run's for {LP_ROTOR.frequency_hz:g} Hz).")
    loss = pole.insertion_loss(EXAMPLE_PYLON)
    insertion = (f"On a pylon of {_sci(EXAMPLE_PYLON, 0)} N/m per pin (no mass; an example value, not a measured pylon) "
                 "the insertion loss is " + " and ".join(
                     f"{_triple(row, '.1f')} dB in x, y, z at {f:g} Hz" for f, row in zip(pole.frequencies_hz, loss, strict=True))
                 + ".")
    return {"impedance example": impedance, "stiff pylon": convergence, "beam modes": beam_modes,
            "beam table": beam_table, "low-frequency springs": springs, "rotor-frequency set": "\n".join(magnitudes),
            "set against run": runs, "set agreement": agreement, "insertion loss": insertion}


def main() -> None:
    path = rewrite_sections(DOCS / DOCUMENT, sections(DOCS / "four-pole.png"))
    print(f"wrote {DOCS / 'four-pole.png'} and the generated sections of {path}")


if __name__ == "__main__":
    main()
