"""Pictures and tables of a mount's layout: links, hinges, loads.

:func:`plot_layout` draws a case in three views (side x-z, front y-z seen
from ahead, top x-y); :func:`link_table` and :func:`hinge_table` list its
links and hinges; :func:`markdown_table` renders a table for the docs.
"""
from __future__ import annotations

import numpy as np

from workbook.model.case import PYLON, Case, HarmonicForce, PointForce, RotatingForce

__all__ = ["plot_layout", "link_table", "hinge_table", "markdown_table"]

_VIEWS = (("side view from the right (x-z)", 0, 2), ("front view from ahead (y-z)", 1, 2),
          ("top view (x-y)", 0, 1))


def _link_colour(name: str) -> str:
    for prefix, colour in (("front", "tab:blue"), ("thrust", "tab:red"), ("rear", "tab:green")):
        if name.startswith(prefix):
            return colour
    return "tab:purple"


def plot_layout(case: Case):
    """Draw the links, hinges, pylon fittings, centre of gravity and loads.

    Parameters
    ----------
    case : Case

    Returns
    -------
    matplotlib.figure.Figure
    """
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(1, 3, figsize=(16, 5.6), constrained_layout=True)
    cg = np.array(case.engine.center_of_mass)
    for ax, (title, i, j) in zip(axes, _VIEWS, strict=True):
        for link in case.links:
            a, b = np.array(link.end_a), np.array(link.end_b)
            ax.plot([a[i], b[i]], [a[j], b[j]], color=_link_colour(link.name), lw=3, solid_capstyle="round")
        for hinge in case.hinges:
            p = np.array(hinge.position)
            style = dict(marker="s", color="k", ms=7) if hinge.on_pylon else dict(marker="o", color="0.3", ms=5)
            ax.plot(p[i], p[j], ls="none", **style)
        ax.plot(cg[i], cg[j], marker="X", color="darkorange", ms=11, ls="none")
        for load in case.static_loads:
            if isinstance(load, PointForce):
                f = np.array(load.force) / np.linalg.norm(load.force) * 0.3
                ax.annotate("", xy=(load.point[i] + f[i], load.point[j] + f[j]), xytext=(load.point[i], load.point[j]),
                            arrowprops=dict(arrowstyle="->", color="darkorange", lw=1.5))
        for excitation in case.single_frequency_excitations()[:4]:
            if isinstance(excitation, (RotatingForce, HarmonicForce)):
                ax.plot(excitation.point[i], excitation.point[j], marker="*", color="crimson", ms=11, ls="none")
        ax.set_title(title)
        ax.set_xlabel("xyz"[i] + " m")
        ax.set_ylabel("xyz"[j] + " m")
        ax.set_aspect("equal", adjustable="datalim")
        ax.grid(True, lw=0.3)
    front = axes[1]
    for link in case.links:
        mid = (np.array(link.end_a) + np.array(link.end_b)) / 2
        front.annotate(link.name, (mid[1], mid[2]), fontsize=7, color=_link_colour(link.name),
                       xytext=(4, 0), textcoords="offset points")
    x_range = [min(p[0] for link in case.links for p in (link.end_a, link.end_b)) - 0.3,
               max(p[0] for link in case.links for p in (link.end_a, link.end_b)) + 0.5]
    for ax in (axes[0], axes[2]):
        ax.plot(x_range, [0, 0], color="0.5", ls="-.", lw=0.8)
        ax.annotate("engine axis", (x_range[1], 0), fontsize=7, color="0.4", ha="right", va="bottom")
    handles = [plt.Line2D([], [], color=c, lw=3, label=label) for label, c in
               (("front links", "tab:blue"), ("rear links", "tab:green"), ("thrust rods", "tab:red"))]
    handles += [plt.Line2D([], [], marker="s", color="k", ls="none", label="pylon-side hinge"),
                plt.Line2D([], [], marker="o", color="0.3", ls="none", label="engine/link hinge"),
                plt.Line2D([], [], marker="X", color="darkorange", ls="none", label="engine CG (thrust arrow)"),
                plt.Line2D([], [], marker="*", color="crimson", ls="none", label="rotor imbalance plane")]
    axes[2].legend(handles=handles, loc="lower left", fontsize=7)
    fig.suptitle(f"{case.name}: {len(case.links)} links, {len(case.hinges)} hinges "
                 f"({len({tuple(np.round(h.position, 6)) for h in case.hinges})} pins); x heading, z up")
    return fig


def link_table(case: Case, reduced: dict | None = None):
    """One row per link: eye centres (mm), length, material, section and, given
    the reduced links, mass and pinned-pinned fundamental frequency.

    Returns
    -------
    pandas.DataFrame
    """
    import pandas as pd

    rows = []
    for link in case.links:
        geometry = getattr(link.model, "geometry", None)
        row = {"link": link.name,
               "eye A (mm)": _mm(link.end_a), "eye B (mm)": _mm(link.end_b),
               "length (mm)": f"{1e3 * link.length:.1f}",
               "material": getattr(getattr(link.model, "material", None), "name", ""),
               "shank (mm)": (f"{1e3 * geometry.shank_width:.0f} x {1e3 * geometry.shank_thickness:.0f}"
                              if geometry is not None else "mesh"),
               "eye radius / bore (mm)": (f"{1e3 * geometry.eye_outer_radius:.0f} / {1e3 * geometry.bore_radius:.0f}"
                                          if geometry is not None else "mesh")}
        if reduced is not None:
            row["mass (kg)"] = f"{reduced[link.name].mass:.2f}"
            row["f1 pinned-pinned (Hz)"] = f"{reduced[link.name].decision.fundamental_hz:.0f}"
        rows.append(row)
    return pd.DataFrame(rows)


def _per_direction(value) -> str:
    """One value, or three (a hinge's directions) separated by slashes."""
    return f"{value:.3g}" if isinstance(value, float) else " / ".join(f"{v:.3g}" for v in value)


def hinge_table(case: Case):
    """One row per hinge: bodies, position (mm), stiffness, damping, clearance.

    Returns
    -------
    pandas.DataFrame
    """
    import pandas as pd

    rows = [{"hinge": h.name, "body A": h.body_a, "body B": h.body_b, "position (mm)": _mm(h.position),
             "pylon side": "yes" if PYLON in h.bodies else "",
             "stiffness (N/m)": _per_direction(h.stiffness), "damping (N s/m)": _per_direction(h.damping),
             "radial clearance (mm)": f"{1e3 * h.radial_clearance:g}"} for h in case.hinges]
    return pd.DataFrame(rows)


def markdown_table(frame) -> str:
    """A pandas DataFrame as a GitHub markdown table (index left out)."""
    header = "| " + " | ".join(str(c) for c in frame.columns) + " |"
    rule = "|" + "|".join("---" for _ in frame.columns) + "|"
    rows = ["| " + " | ".join(str(v) for v in row) + " |" for row in frame.itertuples(index=False)]
    return "\n".join([header, rule, *rows])


def _mm(point) -> str:
    return "(" + ", ".join(f"{1e3 * v:.0f}" for v in point) + ")"
