"""Regenerate the reference-mount figure and tables in docs/.

Writes ``docs/reference-mount.png`` (the layout in three views) and replaces
the generated tables in ``docs/reference-mount.md`` (between the
``<!-- generated: ... -->`` markers) with tables made from
``workbook.model.reference.reference_case()``, so the committed docs are what the
code builds. Run from anywhere::

    python docs/make_reference_docs.py
"""
from __future__ import annotations

from pathlib import Path

import matplotlib

matplotlib.use("Agg")

from generated_sections import replace_section  # noqa: E402

from workbook.model.drawing import hinge_table, link_table, markdown_table, plot_layout  # noqa: E402
from workbook.model.reference import reference_case  # noqa: E402
from workbook.scene.build import build_scene, reduce_links  # noqa: E402
from workbook.solve.modes import linearize, modes_of, mounted_modes  # noqa: E402
from workbook.solve.preload import solve_preload  # noqa: E402

DOCS = Path(__file__).resolve().parent


def main() -> None:
    case = reference_case()
    figure = plot_layout(case)
    figure.savefig(DOCS / "reference-mount.png", dpi=110)

    reduced = reduce_links(case, case.excitations[-1])
    scene = build_scene(case, reduced=reduced)
    preload = solve_preload(scene)
    mounted = mounted_modes(modes_of(linearize(scene)))

    modes = "\n".join(["| mode | frequency (Hz) | damping ratio (%) | engine motion |", "|---|---|---|---|"] + [
        f"| {i + 1} | {m.frequency_hz:.2f} | {100 * m.damping_ratio:.2f} | {m.description} |"
        for i, m in enumerate(mounted)])
    forces = "\n".join(["| hinge | Fx (N) | Fy (N) | Fz (N) |", "|---|---|---|---|"] + [
        f"| {name} | {round(f[0])} | {round(f[1])} | {round(f[2])} |" for name, f in preload.hinge_forces.items()] + [
        f"| **pylon sum** | {round(preload.pylon_force[0])} | {round(preload.pylon_force[1])} | "
        f"{round(preload.pylon_force[2])} |"])

    path = DOCS / "reference-mount.md"
    text = path.read_text()
    for name, content in (("links", markdown_table(link_table(case, reduced))),
                          ("hinges", markdown_table(hinge_table(case))),
                          ("modes", modes), ("static forces", forces)):
        text = replace_section(text, name, content, "reference-mount.md")
    path.write_text(text)
    print(f"wrote {DOCS / 'reference-mount.png'} and the tables of {path}")


if __name__ == "__main__":
    main()
