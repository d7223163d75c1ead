"""Regenerate the reference-mount figure and the generated sections of docs/reference-mount.md.

Writes ``docs/reference-mount.png`` (the layout in three views) and replaces
every generated section of ``docs/reference-mount.md`` (between the
``<!-- generated: ... -->`` markers) with what the code builds and computes
for ``workbook.model.reference.reference_case()``: the tables, and every
number of the prose that the code computes (masses, stiffnesses, mode
frequencies, damping ratios, the preload, the isolation efficiency in the
frequency domain, the hinge damping models side by side, the time-domain
plans, the gyroscopic rotors' effect). ``tests/test_docs_current.py``
regenerates the sections and fails when the committed page differs. Run
from anywhere (a few minutes with an empty link cache)::

    OPENBLAS_NUM_THREADS=1 python docs/make_reference_docs.py
"""
from __future__ import annotations

import dataclasses
import math
from pathlib import Path

import matplotlib
import numpy as np

matplotlib.use("Agg")

from generated_sections import rewrite_sections  # noqa: E402

from flexbodies.exudyn_body import DEFAULT_SPIN_FREQUENCY_HZ  # noqa: E402
from flexbodies.selection import LOW_FREQUENCY_RATIO  # noqa: E402
from workbook.answers.link_stiffness import axial_stiffness  # noqa: E402
from workbook.model.case import AnalysisSettings, Gravity, PointForce  # noqa: E402
from workbook.model.drawing import hinge_table, link_table, markdown_table, plot_layout  # noqa: E402
from workbook.model.reference import HINGE_DAMPING_MODELS, HP_ROTOR, LP_ROTOR, reference_case, reference_sweep  # noqa: E402
from workbook.scene.build import reduce_links  # noqa: E402
from workbook.scene.structural_damping import equivalent_viscous_damping  # noqa: E402
from workbook.solve.modes import mounted_modes  # noqa: E402
from workbook.solve.pipeline import prepare, run_case  # noqa: E402
from workbook.solve.steady_start import REST, STEADY  # noqa: E402
from workbook.solve.time_domain import plan_run  # noqa: E402

DOCS = Path(__file__).resolve().parent
DOCUMENT = "reference-mount.md"
#: The link removed in the topology argument.
LATERAL_LINK = "rear-lateral"
#: Loss factors of bolted and riveted metal joints quoted in the structural-damping
#: literature (Ungar, structural damping, in Beranek and Ver, *Noise and Vibration
#: Control Engineering*): the range the reference hinges' loss factor is chosen from.
JOINT_LOSS_FACTORS = (0.02, 0.1)
#: Share of a mode's kinetic energy in the thrust rods above which the mode is theirs.
ROD_SHARE = 0.8


def _mounted(case, reduced, excitation=HP_ROTOR):
    """Preload and mounted modes of *case* with the reduced links *reduced*, as a run prepares them.

    The one pipeline (stress stiffening included), linearised for the frequency
    domain: the damping ratios include the hinges' loss factors exactly (H).
    Returns the preload, the mounted modes and every mode.
    """
    prepared = prepare(case, excitation, reduced=reduced)
    with prepared.scene:
        return prepared.preload, mounted_modes(prepared.modes), prepared.modes


def _time_plan(case, excitation, reduced):
    """The time-domain plan of one run of *case* from rest (its scene built for the time domain), its
    mounted modes, and the plan of the same run from the steady start."""
    timed = dataclasses.replace(case, analysis=dataclasses.replace(case.analysis, method="time"))
    prepared = prepare(timed, excitation, reduced=reduced, harmonic=False)
    with prepared.scene:
        signal = prepared.scene.excitation.signal
        return plan_run(timed.analysis, signal, prepared.modes, start=REST), mounted_modes(prepared.modes), \
            plan_run(timed.analysis, signal, prepared.modes, start=STEADY)


def _rod_modes(modes):
    """The thrust rods' own modes in the mount."""
    return [m for m in modes if m.body_shares.get("thrust-left", 0) + m.body_shares.get("thrust-right", 0) > ROD_SHARE]


def _around(modes, frequency_hz: float):
    """The mode just below and the mode just above *frequency_hz*."""
    below = max((m for m in modes if m.frequency_hz < frequency_hz), key=lambda m: m.frequency_hz)
    above = min((m for m in modes if m.frequency_hz > frequency_hz), key=lambda m: m.frequency_hz)
    return below, above


def _one(values, what: str) -> float:
    """The single value all hinges share (isotropic and equal), else an error naming *what*."""
    distinct = {tuple(v) for v in values}
    if len(distinct) != 1 or len(set(next(iter(distinct)))) != 1:
        raise ValueError(f"the reference hinges no longer share one isotropic {what}: the page's argument needs it")
    return next(iter(distinct))[0]


def _sci(value: float) -> str:
    """*value* as ``2.0e7``: one decimal, no exponent padding."""
    mantissa, exponent = f"{value:.1e}".split("e")
    return f"{mantissa}e{int(exponent)}"


def _range(values, digits: int) -> str:
    low, high = min(values), max(values)
    return f"{low:.{digits}f}" if round(low, digits) == round(high, digits) else f"{low:.{digits}f}-{high:.{digits}f}"


def _engine(case) -> str:
    engine = case.engine
    inertia = np.asarray(engine.inertia)
    gravity = next(load for load in case.static_loads if isinstance(load, Gravity))
    g = -gravity.acceleration[2]
    roll, pitch = (math.sqrt(inertia[i, i] / engine.mass) for i in (0, 1))
    cg = ", ".join(f"{1e3 * v:.0f}" for v in engine.center_of_mass)
    rows = [
        ("mass", f"{engine.mass:.0f} kg",
         f"{engine.mass * g / 1e3:.1f} kN at g = {g:g} m/s^2 (seed study: gravity -35 kN); a CFM56 (dry ~2.4 t) "
         "with nacelle, EBU and fluids"),
        ("centre of gravity", f"({cg}) mm",
         f"{-engine.center_of_mass[0]:.2f} m aft of the front mount (the heavy fan module is forward; the front "
         f"mount takes about 2/3 of the weight), {-1e3 * engine.center_of_mass[2]:.0f} mm below the axis "
         "(accessory gearbox under the fan case)"),
        ("roll inertia Ixx", f"{inertia[0, 0]:.1f} kg m^2",
         f"radius of gyration {roll:.2f} m: casings and rotors of 0.4-0.85 m radius (fan diameter ~1.7 m)"),
        ("pitch, yaw inertia Iyy = Izz", f"{inertia[1, 1]:.0f} kg m^2",
         f"radius of gyration {pitch:.2f} m: a 2.5 m long body (uniform rod: L/sqrt(12) = "
         f"{2.5 / math.sqrt(12):.2f} m) with the fan forward"),
        ("products of inertia", f"{np.abs(inertia - np.diag(np.diag(inertia))).max():g}",
         "axisymmetric engine; the gearbox is neglected"),
    ]
    return "\n".join(["| quantity | value | where it comes from |", "|---|---|---|"]
                     + [f"| {a} | {b} | {c} |" for a, b, c in rows])


def _topology(case) -> str:
    """Counts and the geometry the topology argument uses, from the case."""
    links = case.link_map
    pins = {tuple(np.round(h.position, 6)) for h in case.hinges}
    front_a, front_b = (np.array(p) for p in (links["front-left"].end_a, links["front-left"].end_b))
    lean = math.degrees(math.atan2(abs(front_b[1] - front_a[1]), front_b[2] - front_a[2]))
    # the front V's lines meet in the plane y = 0
    below = front_a[1] * (front_b[2] - front_a[2]) / (front_b[1] - front_a[1])
    rear, lateral = links["rear-left"].end_a, links["rear-lateral"]
    return (f"The case: {len(case.links)} links, {len(case.hinges)} hinges ({len(case.pylon_hinges)} on the pylon "
            f"side) at {len(pins)} pins. Front mount plane x = {front_a[0]:.2f} m, the V links "
            f"{lean:.0f} deg off vertical, their lines meeting {below:.2f} m below the engine eyes; rear mount plane "
            f"x = {rear[0]:.2f} m, rear-left/right {2 * rear[1]:.2f} m apart; rear-lateral "
            f"{rear[0] - lateral.end_a[0]:.2f} m aft of it, its engine eye at y = {1e3 * lateral.end_a[1]:+.0f} mm and "
            f"its pylon eye at y = {1e3 * lateral.end_b[1]:+.0f} mm; the thrust rods' forward eyes at "
            f"x = {links['thrust-left'].end_a[0]:.2f} m.")


def _links(case, reduced, per_rotor) -> tuple[str, str]:
    """The links table (with each link's axial stiffness) and the paragraph on the low-frequency rule."""
    table = link_table(case, reduced)
    table["axial stiffness (GN/m)"] = [f"{axial_stiffness(reduced[link.name]) / 1e9:.2f}" for link in case.links]
    thrust = [link.name for link in case.links if link.name.startswith("thrust")]
    short = [link.name for link in case.links if link.name not in thrust]
    fundamental = {name: item.decision.fundamental_hz for name, item in reduced.items()}
    ratios = {rotor.name: max(rotor.frequency_hz / fundamental[name] for name in short) for rotor in per_rotor}
    kept = {rotor.name: {per_rotor[rotor][name].n_fixed_interface for name in thrust} for rotor in per_rotor}
    geometry = case.link_map[thrust[0]].model.geometry
    model = case.link_map[short[0]].model
    rod = case.link_map[thrust[0]].model
    text = (
        f"The {len(short)} short links are {model.material.name} ({model.material.youngs_modulus / 1e9:.0f} GPa, "
        f"{model.material.density:.0f} kg/m^3) with a {1e3 * model.geometry.shank_width:.0f} x "
        f"{1e3 * model.geometry.shank_thickness:.0f} mm shank, {1e3 * model.geometry.eye_outer_radius:.0f} mm eye "
        f"radius, {1e3 * model.geometry.bore_radius:.0f} mm bore and {1e3 * model.geometry.thickness:.0f} mm eye "
        f"thickness; their pinned-pinned fundamentals (spin restrained, the boundary condition they have in the "
        f"mount) are {_range([fundamental[n] for n in short], 0)} Hz, so the low-frequency rule "
        f"(f_exc < {LOW_FREQUENCY_RATIO:g} f1) holds at both rotor frequencies (f_exc / f1 at most "
        + " and ".join(f"{ratios[r.name]:.3f} at {r.frequency_hz:g} Hz" for r in per_rotor)
        + f") and they keep static modes only. The thrust rods are longer "
        f"({_range([case.link_map[n].length for n in thrust], 2)} m) and {rod.material.name} with a "
        f"{1e3 * geometry.shank_width:.0f} x {1e3 * geometry.shank_thickness:.0f} mm shank: their first bending "
        f"mode is at {_range([fundamental[n] for n in thrust], 0)} Hz, so the rule fails at both rotor "
        f"frequencies and \"auto\" keeps fixed-interface modes up to 4 x f_exc ("
        + ", ".join(f"{'/'.join(map(str, sorted(kept[r.name])))} kept at {r.frequency_hz:g} Hz" for r in per_rotor)
        + ").")
    return markdown_table(table), text


def _hinges(case, reduced, mounted) -> str:
    """The paragraph on the hinge stiffness."""
    k = _one((h.values("stiffness") for h in case.hinges), "stiffness")
    links = {link.name: axial_stiffness(reduced[link.name]) for link in case.links}
    series = {name: 100 * (k / 2) / value for name, value in links.items()}   # link compliance / two hinges'
    first, last = mounted[0], mounted[-1]
    return (
        f"All {len(case.hinges)} hinges have the same spherical-bearing-plus-fitting stiffness, **k = {_sci(k)} N/m** "
        f"in every direction, chosen so that the engine's {len(mounted)} mounted modes lie at "
        f"{first.frequency_hz:.1f}-{last.frequency_hz:.1f} Hz, well below the LP rotor's {LP_ROTOR.frequency_hz:g} Hz "
        f"(ratio {LP_ROTOR.frequency_hz / last.frequency_hz:.1f} for the highest): the mount isolates at both rotor "
        f"frequencies. The links themselves are far stiffer axially (from the FE: "
        + ", ".join(f"{links[n] / 1e9:.2f} GN/m {n}" for n in ("front-left", "rear-left", "thrust-left"))
        + f"): in series with a link's two hinges its compliance adds {_range(series.values(), 1)} % "
        f"(the thrust rods the most).")


def _hinge_damping(case, viscous_case, mounted, viscous_mounted) -> tuple[str, str]:
    """The paragraphs on the loss factor (with its reason) and on the former viscous damping."""
    k = _one((h.values("stiffness") for h in case.hinges), "stiffness")
    eta = _one((h.values("loss_factor") for h in case.hinges), "loss factor")
    _one((h.values("damping") for h in case.hinges), "viscous damping")   # none in the reference
    low, high = JOINT_LOSS_FACTORS
    if not low <= eta <= high:
        raise ValueError(f"the reference hinges' loss factor {eta:g} lies outside the quoted range {low:g}-{high:g}")
    zeta = [100 * m.damping_ratio for m in mounted]
    loss = (
        f"Damping is structural: every hinge has the **loss factor eta = {eta:g}** (`HINGE_LOSS_FACTOR`), its "
        f"stiffness acting as k (1 + i eta), and {'no' if not case.hinges[0].damping else 'a'} viscous damper. A "
        f"bolted or riveted metal joint dissipates energy by micro-slip and friction at its contact faces; the loss "
        f"factor of such built-up steel and titanium structures lies at about {low:g}-{high:g} and hardly changes "
        f"with frequency (the range quoted for bolted and riveted joints in the structural-damping literature, e.g. "
        f"Ungar's chapter on structural damping in Beranek and Ver, *Noise and Vibration Control Engineering*); "
        f"{eta:g} is the middle of it, for a spherical bearing clamped in a bolted fitting. Linearised with the "
        f"structural matrix H (the frequency domain's exact form), it gives the mounted modes zeta = "
        f"{_range(zeta, 2)} % (eta / 2 = {100 * eta / 2:g} % for a mode whose strain energy is all in the hinges; "
        f"table below), the same at every frequency.")
    beta = _one((h.values("damping") / h.values("stiffness") for h in viscous_case.hinges), "damping time")
    omega = {rotor.frequency_hz: 2 * math.pi * rotor.frequency_hz for rotor in (LP_ROTOR, HP_ROTOR)}
    first, last = viscous_mounted[0], viscous_mounted[-1]
    viscous = (
        f"The former model, **d = beta k with beta = {_sci(beta)} s** ({_sci(beta * k)} N s/m per hinge; "
        f"`reference_case(hinge_damping=\"viscous\")`), gave zeta = beta w / 2 from "
        f"{100 * first.damping_ratio:.1f} % ({first.frequency_hz:.1f} Hz) to {100 * last.damping_ratio:.1f} % "
        f"({last.frequency_hz:.1f} Hz) at the mounted modes, but its equivalent loss factor beta w grows with the "
        f"frequency: " + " and ".join(f"{beta * w:.2f} at {f:g} Hz" for f, w in omega.items())
        + f", where the dampers passed more force than the springs (the damper term sqrt(1 + (beta w)^2) is "
        f"{math.sqrt(1 + (beta * omega[HP_ROTOR.frequency_hz]) ** 2):.1f} at {HP_ROTOR.frequency_hz:g} Hz) and "
        f"the HP transmissibility came out too high. The viscous beta therefore goes: a bolted joint has no "
        f"velocity-proportional damper, and keeping one would bring the frequency-growing force back. The two "
        f"models side by side are in \"Damping models\" below.")
    return loss, viscous


def _time_domain_damping(case, plans, viscous_plans) -> str:
    """The loss factor in the time domain: its viscous equivalent per run and the settle times it implies."""
    k = _one((h.values("stiffness") for h in case.hinges), "stiffness")
    eta = _one((h.values("loss_factor") for h in case.hinges), "loss factor")
    rotors = (LP_ROTOR, HP_ROTOR)
    least = {rotor: min(plans[rotor][1], key=lambda m: m.decay_rate) for rotor in rotors}
    settle = {rotor: plans[rotor][0].settle_periods / rotor.frequency_hz for rotor in rotors}
    former = {rotor: viscous_plans[rotor][0].settle_periods / rotor.frequency_hz for rotor in rotors}
    steps = {rotor: plans[rotor][0].steps / viscous_plans[rotor][0].steps for rotor in rotors}
    constants = case.analysis.settle_time_constants
    return (
        "In the frequency domain (the default for this linear scene) the loss factor is exact at every frequency. "
        "The time domain uses its viscous equivalent d = eta k / w at the run's own frequency ("
        + " and ".join(f"{_sci(equivalent_viscous_damping(eta, k, r.frequency_hz))} N s/m per hinge at "
                       f"{r.frequency_hz:g} Hz" for r in rotors)
        + "), exact in the steady state there but far weaker at the mounted modes (the least damped: zeta "
        + ", ".join(f"{100 * least[r].damping_ratio:.2f} % at {least[r].frequency_hz:.1f} Hz in the {r.name} run"
                    for r in rotors)
        + f"), so a time-domain run from rest would settle {constants:g} decay time constant(s) of "
        + " and ".join(f"{settle[r]:.0f} s ({r.name})" for r in rotors)
        + f" instead of {_range(former.values(), 1)} s with the former viscous damping: "
        + " and ".join(f"{steps[r]:.0f}" for r in rotors)
        + " times the steps. A run therefore starts, by default, in the steady state of its own linearised scene "
        "(Time-domain method, below), which leaves nothing to settle. The model card of each run says which form "
        "was built and at which frequency, and where the run started.")


def _hinge_rows(case) -> str:
    """The hinge table with each hinge's loss factor."""
    table = hinge_table(case)
    table.insert(list(table.columns).index("damping (N s/m)") + 1, "loss factor",
                 [" / ".join(f"{v:g}" for v in h.values("loss_factor")) if not h.isotropic
                  else f"{h.values('loss_factor')[0]:g}" for h in case.hinges])
    return markdown_table(table)


def _loads(case, reduced) -> str:
    thrust = next(load for load in case.static_loads if isinstance(load, PointForce))
    gravity = next(load for load in case.static_loads if isinstance(load, Gravity))
    sweep = reference_sweep()
    frequencies = sweep.frequencies_hz
    lines = [
        f"- Static: heading thrust {thrust.force[0] / 1e3:g} kN on the engine axis (at x = {thrust.point[0]:g} m) "
        f"and gravity ({-gravity.acceleration[2]:g} m/s^2 on the engine and on every link; the links add "
        f"{sum(item.mass for item in reduced.values()):.2f} kg).",
        f"- LP rotor: {LP_ROTOR.amplitude:g} N rotating in the lateral-vertical plane, right-handed about +x (y at "
        f"t = 0, then z), at {LP_ROTOR.frequency_hz:g} Hz, in the fan plane x = {LP_ROTOR.point[0]:+.2f} m, "
        f"{LP_ROTOR.point[0] - case.engine.center_of_mass[0]:.2f} m ahead of the centre of gravity (the fan "
        f"dominates the LP rotor's imbalance).",
        f"- HP rotor: the same at {HP_ROTOR.frequency_hz:g} Hz in the plane x = {HP_ROTOR.point[0]:+.2f} m, on the "
        f"HP compressor/turbine near the centre of gravity.",
        f"- `reference_case(sweep=True)` adds a sweep: the rotating {sweep.template.amplitude:g} N at the centre of "
        f"gravity at {len(frequencies)} frequencies from {min(frequencies):g} to {max(frequencies):g} Hz "
        f"(log-spaced; a sweep on this linear scene is answered in the frequency domain).",
    ]
    return "\n".join(lines)


def _lowest(mounted) -> str:
    return (f"The reference mount has none: its lowest mode is the first mounted mode at "
            f"{mounted[0].frequency_hz:.2f} Hz (the links' spin restraints sit at {DEFAULT_SPIN_FREQUENCY_HZ:g} Hz).")


def _without_lateral(case, reduced, first_hz: float) -> str:
    reduced = {name: item for name, item in reduced.items() if name != LATERAL_LINK}
    _, mounted, _ = _mounted(case.without_link(LATERAL_LINK), reduced)
    return (f"Without `{LATERAL_LINK}` the first mounted mode ({mounted[0].description}) drops to "
            f"{mounted[0].frequency_hz:.2f} Hz, from {first_hz:.2f} Hz (the same flexible links and preload, "
            f"geometric stiffness included).")


def _modes(mounted) -> str:
    return "\n".join(["| mode | frequency (Hz) | damping ratio (%) | engine motion |", "|---|---|---|---|"] + [
        f"| {i + 1} | {m.frequency_hz:.2f} | {100 * m.damping_ratio:.2f} | {m.description} |"
        for i, m in enumerate(mounted)])


def _forces(preload) -> str:
    return "\n".join(["| hinge | Fx (N) | Fy (N) | Fz (N) |", "|---|---|---|---|"] + [
        f"| {name} | {round(f[0])} | {round(f[1])} | {round(f[2])} |" for name, f in preload.hinge_forces.items()] + [
        f"| **pylon sum** | {round(preload.pylon_force[0])} | {round(preload.pylon_force[1])} | "
        f"{round(preload.pylon_force[2])} |"])


#: The balance is quoted against this bound, not by its own value: a round-off residual differs
#: from machine to machine in its last digit.
ROUND_OFF_BALANCE = 1e-12


def _balance(case, preload) -> str:
    if not preload.relative_mismatch < ROUND_OFF_BALANCE:
        raise ValueError(f"the preload balance {preload.relative_mismatch:.1e} is no longer round-off")
    return (f"Their pylon sum equals the applied loads to round-off (below {ROUND_OFF_BALANCE:g} relative); the "
            f"run stops if it misses by more than {case.analysis.equilibrium_tolerance:g}.")


def _efficiency(results) -> tuple[str, str]:
    """The efficiency table (frequency domain) and the flexible-vs-rigid change of T."""
    rows = ["| links | run | f (Hz) | eta x (%) | eta y (%) | eta z (%) |", "|---|---|---|---|---|---|"]
    for label, result in results.items():
        for run in result.runs:
            rows.append(f"| {label} | {run.name} | {run.frequency_hz:g} | "
                        + " | ".join(f"{e:.2f}" for e in run.efficiency) + " |")
    flexible, rigid = results.values()
    change = ["| run | T x, y, z with flexible links | change from rigid links (%) |", "|---|---|---|"]
    for run in flexible.runs:
        t, reference = run.transmissibility, rigid.run(run.name).transmissibility
        change.append(f"| {run.name} | " + ", ".join(f"{v:.4g}" for v in t) + " | "
                      + ", ".join(f"{v:+.1f}" for v in 100 * (t / reference - 1)) + " |")
    return "\n".join(rows), "\n".join(change)


def _damping_models(results) -> str:
    """T in dB per direction of the LP and HP runs under each hinge damping model (frequency domain)."""
    rows = ["| hinge damping | run | f (Hz) | T x (dB) | T y (dB) | T z (dB) | mounted-mode zeta (%) |",
            "|---|---|---|---|---|---|---|"]
    for model in HINGE_DAMPING_MODELS[::-1]:
        result = results[model]
        for run in result.runs:
            zeta = [100 * z for _, z, _ in result.model_cards[run.name].mounted_modes]
            db = 20 * np.log10(run.transmissibility)
            rows.append(f"| {model} | {run.name} | {run.frequency_hz:g} | {db[0]:.2f} | {db[1]:.2f} | {db[2]:.2f} | "
                        f"{_range(zeta, 2)} |")
    old, new = results["viscous"], results["loss factor"]
    for run in new.runs:
        change = 20 * np.log10(run.transmissibility / old.run(run.name).transmissibility)
        rows.append(f"| change | {run.name} | {run.frequency_hz:g} | {change[0]:+.2f} | {change[1]:+.2f} | "
                    f"{change[2]:+.2f} | |")
    return "\n".join(rows)


def _damping_change(results, rod_modes) -> str:
    """What the change of damping model does at each rotor frequency, and why the heading force at HP moves."""
    old, new = results["viscous"], results["loss factor"]
    change = {run.name: 20 * np.log10(run.transmissibility / old.run(run.name).transmissibility) for run in new.runs}
    hp = HP_ROTOR.name
    pairs = {model: _around(rod_modes[model], HP_ROTOR.frequency_hz) for model in HINGE_DAMPING_MODELS}
    frequencies = " and ".join(f"{m.frequency_hz:.0f}" for m in pairs["loss factor"])
    zeta = {model: _range([100 * m.damping_ratio for m in pair], 1) for model, pair in pairs.items()}
    words = "rises" if change[hp][0] > 0 else "falls"
    return (
        "From the former to the new model T changes by "
        + "; ".join(f"{', '.join(f'{v:+.1f}' for v in change[run.name])} dB in x, y, z at {run.frequency_hz:g} Hz"
                    for run in new.runs)
        + f" (negative: less force reaches the pylon). At {HP_ROTOR.frequency_hz:g} Hz the heading force {words}: "
        f"the thrust rods' bending modes in the mount on either side of it, at {frequencies} Hz, were damped at "
        f"{zeta['viscous']} % of critical by the former dampers and are at {zeta['loss factor']} % with the loss "
        f"factor (T_x {new.run(hp).transmissibility[0]:.2g}).")


def _settings(case, plans) -> str:
    """The time-domain settings and what they plan for the reference's two runs (nothing integrated)."""
    analysis = case.analysis
    return (f"Settings: {analysis.steps_per_period} steps per period (generalized-alpha, spectral radius "
            f"{analysis.spectral_radius:g}, whose period error makes a mass-dominated T about "
            f"(2 pi / n)^2 / 6 = {100 * (2 * math.pi / analysis.steps_per_period) ** 2 / 6:.2f} % low), a "
            f"start in the steady state of the run's own linearised scene (`start` \"auto\": the scene is linear), "
            f"then two windows of {analysis.measured_periods} periods; the run is steady when the complex amplitudes "
            f"of the two windows agree within {100 * analysis.steady_tolerance:g} %, and goes on window by window "
            f"while they do not, at most as long as a start from rest would settle. For the reference (flexible links) "
            f"that plans "
            + " and ".join(f"{steady.steps:,} steps ({steady.end_time:.2g} s simulated) for the {rotor.name}"
                           .replace(",", " ") for rotor, (_, _, steady) in plans.items())
            + f". From rest (`start` \"rest\": a {analysis.ramp_periods:g}-period smooth start and a settle time of "
            f"{analysis.settle_time_constants:g} decay time constant(s) 1 / (zeta w) of the least damped mounted mode "
            f"of the time-domain scene before the two windows, which must then agree in magnitude) it plans "
            + " and ".join(f"{rest.steps:,} steps ({rest.end_time:.0f} s simulated) for the {rotor.name}"
                           .replace(",", " ") for rotor, (rest, _, _) in plans.items())
            + ".")


def _rotors(case) -> tuple[str, str]:
    """The gyroscopic rotors: their numbers, the T table (frequency domain), the mounted modes and a time-domain check."""
    spun = reference_case(rotors=True)
    inertia = np.asarray(case.engine.inertia)[1, 1]
    momentum = {rotor.name: rotor.polar_inertia * 2 * math.pi * rotor.frequency_hz for rotor in spun.rotors}
    numbers = (
        ", ".join(f"{rotor.name} Ip = {rotor.polar_inertia:g} kg m^2 at {rotor.frequency_hz:g} Hz"
                  for rotor in spun.rotors)
        + ". Spin angular momentum: " + " + ".join(f"{h:,.0f}".replace(",", " ") for h in momentum.values())
        + f" = {sum(momentum.values()):,.0f}".replace(",", " ") + f" kg m^2/s, against a pitch and yaw inertia of "
        f"{inertia:.0f} kg m^2: h / (I_t w) = "
        + " and ".join(
            f"{sum(momentum.values()) / (inertia * 2 * math.pi * f):.3f} at {f:g} Hz"
            for f in (LP_ROTOR.frequency_hz, HP_ROTOR.frequency_hz)) + ".")
    frequency = AnalysisSettings(method="frequency")
    rows = ["| links | run | rotors | T_x | T_y | T_z | change x, y, z (%) |", "|---|---|---|---|---|---|---|"]
    for links in ("rigid", "flexible"):
        answers = {}
        for rotors in (False, True):
            subject = reference_case(rotors=rotors, analysis=frequency)
            answers[rotors] = run_case(subject.with_rigid_links() if links == "rigid" else subject)
        for run in answers[False].runs:
            for rotors, result in answers.items():
                t = result.run(run.name).transmissibility
                change = ", ".join(f"{v:+.1f}" for v in 100 * (t / run.transmissibility - 1)) if rotors else ""
                rows.append(f"| {links} | {run.name} {run.frequency_hz:g} Hz | {'yes' if rotors else 'no'} | "
                            + " | ".join(f"{v:.5f}" for v in t) + f" | {change} |")
    modes = {}
    for rotors in (False, True):
        subject = reference_case(rotors=rotors).with_rigid_links()
        modes[rotors] = _mounted(subject, reduce_links(subject, subject.excitations[-1]))[1]
    lp = dataclasses.replace(spun.with_rigid_links(), excitations=(LP_ROTOR,), analysis=AnalysisSettings(method="time"))
    timed = run_case(lp).runs[0].transmissibility
    spectral = run_case(dataclasses.replace(lp, analysis=frequency)).runs[0].transmissibility
    check = (
        "Mounted modes (rigid links): "
        + ", ".join(f"{m.frequency_hz:.2f}" for m in modes[False]) + " Hz without the rotors, "
        + ", ".join(f"{m.frequency_hz:.2f}" for m in modes[True]) + " Hz with them. The time domain (rigid links, "
        f"{lp.analysis.steps_per_period} steps per period) gives T = ("
        + ", ".join(f"{v:.5f}" for v in timed) + f") at {LP_ROTOR.frequency_hz:g} Hz with the rotors, "
        + ", ".join(f"{v:+.1f}" for v in 100 * (timed / spectral - 1)) + " % from the frequency domain.")
    return numbers, "\n".join(rows), check


def sections() -> dict[str, str]:
    """Every generated section of docs/reference-mount.md, by name."""
    case = reference_case()
    viscous_case = reference_case(hinge_damping="viscous")
    rotors = (LP_ROTOR, HP_ROTOR)
    per_rotor = {rotor: reduce_links(case, rotor) for rotor in rotors}
    reduced = per_rotor[HP_ROTOR]
    preload, mounted, modes = _mounted(case, reduced)
    _, viscous_mounted, viscous_modes = _mounted(viscous_case, reduced)
    links, rule = _links(case, reduced, per_rotor)
    loss, viscous = _hinge_damping(case, viscous_case, mounted, viscous_mounted)
    plans = {rotor: _time_plan(case, rotor, per_rotor[rotor]) for rotor in rotors}
    viscous_plans = {rotor: _time_plan(viscous_case, rotor, per_rotor[rotor]) for rotor in rotors}
    flexible = run_case(case)
    efficiency, change = _efficiency({"flexible (auto modes)": flexible, "rigid (`--rigid`)": run_case(case.with_rigid_links())})
    by_model = {"loss factor": flexible, "viscous": run_case(viscous_case)}
    rod_modes = {"loss factor": _rod_modes(modes), "viscous": _rod_modes(viscous_modes)}
    numbers, rotor_table, rotor_check = _rotors(case)
    return {
        "engine": _engine(case),
        "topology": _topology(case),
        "lowest mode": _lowest(mounted),
        "without rear-lateral": _without_lateral(case, reduced, mounted[0].frequency_hz),
        "link rule": rule,
        "links": links,
        "hinge stiffness": _hinges(case, reduced, mounted),
        "hinge damping": loss,
        "former damping": viscous,
        "time-domain damping": _time_domain_damping(case, plans, viscous_plans),
        "hinges": _hinge_rows(case),
        "loads": _loads(case, reduced),
        "modes": _modes(mounted),
        "balance": _balance(case, preload),
        "static forces": _forces(preload),
        "efficiency": efficiency,
        "flexibility": change,
        "damping models": _damping_models(by_model),
        "damping change": _damping_change(by_model, rod_modes),
        "time-domain settings": _settings(case, plans),
        "rotor numbers": numbers,
        "rotor table": rotor_table,
        "rotor check": rotor_check,
    }


def main() -> None:
    figure = plot_layout(reference_case())
    figure.savefig(DOCS / "reference-mount.png", dpi=110)
    path = rewrite_sections(DOCS / DOCUMENT, sections())
    print(f"wrote {DOCS / 'reference-mount.png'} and the generated sections of {path}")


if __name__ == "__main__":
    main()
