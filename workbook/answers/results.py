"""Answers of a mount run: amplitudes, transmissibility, isolation efficiency.

The formulas (T, eta, dB, the pylon sum) live in :mod:`workbook.answers.isolation`.
The pylon force is the vector sum of the pylon-side hinge forces, or of the test rig's
transducer forces when the case has them (``Scene.pylon_channels``).
:class:`MountResult` tabulates itself (pandas), plots itself (matplotlib)
and converts to JSON-ready data.
"""
from __future__ import annotations

import json
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

import numpy as np

from workbook._renamed import renamed
from workbook.answers.isolation import efficiency, level_db, transmissibility
from workbook.model.case import DIRECTIONS

if TYPE_CHECKING:
    from workbook.answers.model_card import ModelCard
    from workbook.solve.preload import Preload

__all__ = ["ExcitationResult", "MountResult", "PylonAnswers", "PYLON_SUM", "LONG_COLUMNS"]

#: Row label of the pylon sum in the tables.
PYLON_SUM = "pylon sum"
#: Columns of the answers in long form (:meth:`MountResult.long_rows`, ``MountResult.to_pandas("all")``).
LONG_COLUMNS = ("run", "frequency Hz", "location", "pylon side", "direction", "amplitude N", "T", "eta %", "dB")


class PylonAnswers:
    """Transmissibility and isolation efficiency of a pylon force.

    For any answer holding ``pylon_amplitude`` (N, per direction x, y, z)
    and ``excitation_amplitude`` (N): a simulated run or a rig measurement.
    """

    pylon_amplitude: np.ndarray
    excitation_amplitude: float

    @property
    def transmissibility(self) -> np.ndarray:
        """Pylon-force transmissibility per direction x, y, z."""
        return transmissibility(self.pylon_amplitude, self.excitation_amplitude)

    @property
    def efficiency(self) -> np.ndarray:
        """Pylon isolation efficiency per direction, %."""
        return efficiency(self.transmissibility)


@dataclass
class ExcitationResult(PylonAnswers):
    """Answers and histories of one excitation run.

    Attributes
    ----------
    name : str
        Excitation name.
    frequency_hz : float
    excitation_amplitude : float
        ``|F_exc|``, N.
    pylon_amplitude : ndarray, shape (3,)
        Amplitude of the pylon force at the excitation frequency, N.
    hinge_amplitudes : dict of str to ndarray, shape (3,)
        Amplitude of each hinge force, N.
    pylon_hinges : list of str
        The force channels summed into the pylon force: the pylon-side hinges,
        or the test rig's transducers when the case has them.
    steady_change : float
        Relative change of the pylon amplitudes between the last two windows.
    steady_tolerance : float
    warnings : list of str
    time : ndarray, shape (n,)
        s; time-domain answers only (empty in the frequency domain, as the
        histories below).
    hinge_histories : dict of str to ndarray, shape (n, 3)
        N.
    pylon_history : ndarray, shape (n, 3)
        N.
    excitation_history : ndarray, shape (n, 3)
        N.
    window : slice
        Samples of the measured (last) window.
    hinge_phasors : dict of str to ndarray, complex, shape (3,)
        Complex amplitude of each force channel, N: frequency-domain answers
        only (empty for a time-domain run).
    truncation_error : ndarray, shape (3,), or None
        Estimated relative error of T per direction that the links' omitted
        fixed-interface modes leave (:mod:`workbook.solve.truncation`);
        None when not estimated (time domain, flexible pylon).
    link_phasors : dict of str to ndarray, complex, shape (n_modes,)
        Complex amplitude of each flexible link's modal coordinates, whose
        stress is ``S q`` (:func:`flexbodies.stress.state_stress`):
        frequency-domain answers on a rigid pylon only (else empty).
    model_card : ModelCard
        How the run was computed (None only before a solver attaches it).
    preload : workbook.solve.preload.Preload
        The preloaded equilibrium the run starts from (None as the card).
    """

    name: str
    frequency_hz: float
    excitation_amplitude: float
    pylon_amplitude: np.ndarray
    hinge_amplitudes: dict
    pylon_hinges: list
    steady_change: float
    steady_tolerance: float
    warnings: list
    time: np.ndarray = field(default_factory=lambda: np.zeros(0), repr=False)
    hinge_histories: dict = field(default_factory=dict, repr=False)
    pylon_history: np.ndarray = field(default_factory=lambda: np.zeros((0, 3)), repr=False)
    excitation_history: np.ndarray = field(default_factory=lambda: np.zeros((0, 3)), repr=False)
    window: slice = field(default_factory=lambda: slice(0, 0), repr=False)
    hinge_phasors: dict = field(default_factory=dict, repr=False)
    truncation_error: np.ndarray | None = field(default=None, repr=False)
    link_phasors: dict = field(default_factory=dict, repr=False)
    model_card: ModelCard | None = field(default=None, repr=False)
    preload: Preload | None = field(default=None, repr=False)

    @property
    def has_histories(self) -> bool:
        """True for a time-domain answer, which keeps its force histories."""
        return len(self.time) > 0

    @property
    def steady(self) -> bool:
        return self.steady_change <= self.steady_tolerance

    def amplitudes(self) -> dict[str, np.ndarray]:
        """Amplitudes of every hinge and of the pylon sum (last), N."""
        return {**self.hinge_amplitudes, PYLON_SUM: self.pylon_amplitude}


@dataclass
class MountResult:
    """All runs of a case, each with its model card and preload.

    Attributes
    ----------
    case_name : str
    runs : list of ExcitationResult
    """

    case_name: str
    runs: list

    @property
    def model_cards(self) -> dict[str, ModelCard]:
        """The model card of each run, by run name."""
        return {run.name: run.model_card for run in self.runs if run.model_card is not None}

    @property
    def preloads(self) -> dict[str, Preload]:
        """The preload of each run, by run name."""
        return {run.name: run.preload for run in self.runs if run.preload is not None}

    def run(self, name: str | None = None) -> ExcitationResult:
        """The run named *name* (default: the first)."""
        if name is None:
            return self.runs[0]
        for run in self.runs:
            if run.name == name:
                return run
        raise KeyError(f"no run {name!r}; runs: {', '.join(r.name for r in self.runs)}")

    def to_pandas(self, quantity: str = "efficiency"):
        """The answers as a table.

        Parameters
        ----------
        quantity : {"efficiency", "transmissibility", "db", "amplitude", "all"}
            Isolation efficiency (%), T, 20 log10 T (dB) or amplitude (N) of
            the pylon force: one row per run, columns frequency (Hz) and x,
            y, z. ``"all"``: every answer in long form, one row per run,
            location (hinge or pylon sum) and direction, with amplitude (N),
            T, eta (%) and dB.

        Returns
        -------
        pandas.DataFrame
        """
        import pandas as pd

        if quantity == "all":
            return self._long_frame()
        rows, columns = self._table_rows(quantity)
        return pd.DataFrame.from_dict(rows, orient="index", columns=columns).rename_axis("run")

    def _table_rows(self, quantity: str) -> tuple[dict[str, list[float]], list[str]]:
        """The rows (run name -> frequency and x, y, z) and the columns of :meth:`to_pandas`."""
        values = {"efficiency": lambda r: r.efficiency, "transmissibility": lambda r: r.transmissibility,
                  "db": lambda r: level_db(r.transmissibility), "amplitude": lambda r: r.pylon_amplitude}
        if quantity not in values:
            raise ValueError(f"quantity must be one of {', '.join(values)}, all, got {quantity!r}")
        units = {"efficiency": "eta %", "transmissibility": "T", "db": "dB", "amplitude": "N"}
        rows = {run.name: [run.frequency_hz, *values[quantity](run)] for run in self.runs}
        columns = ["frequency Hz"] + [f"{units[quantity]} {d}" for d in DIRECTIONS]
        return rows, columns

    def to_text(self, quantity: str = "efficiency", *, frequency: bool = True,
                float_format=lambda v: f"{v:8.2f}") -> str:
        """:meth:`to_pandas` as text, as ``to_pandas(quantity).to_string(float_format=float_format)``
        gives it, without importing pandas for a table of finite numbers.

        Parameters
        ----------
        quantity : {"efficiency", "transmissibility", "db", "amplitude"}
        frequency : bool
            False leaves out the frequency column.
        float_format : callable
            Text of one value.
        """
        from workbook.answers.text_table import text_table

        rows, columns = self._table_rows(quantity)
        if not frequency:
            rows, columns = {name: values[1:] for name, values in rows.items()}, columns[1:]
        text = text_table("run", rows, columns, float_format) if len(rows) == len(self.runs) else None
        if text is not None:
            return text
        table = self.to_pandas(quantity)
        return (table if frequency else table.drop(columns="frequency Hz")).to_string(float_format=float_format)

    def long_rows(self) -> list[tuple]:
        """Every answer in long form, one row per run, location (hinge or pylon sum) and direction, of
        plain Python values (:data:`LONG_COLUMNS`): the rows of ``to_pandas("all")``, without pandas."""
        rows = []
        for run in self.runs:
            for location, amplitude in run.amplitudes().items():
                for axis, value in zip(DIRECTIONS, amplitude, strict=True):
                    t = transmissibility(value, run.excitation_amplitude)
                    rows.append((run.name, float(run.frequency_hz), location, bool(location == PYLON_SUM
                                 or location in run.pylon_hinges), axis, float(value), float(t),
                                 float(efficiency(t)), float(level_db(t))))
        return rows

    def _long_frame(self):
        """Every answer in long form (``to_pandas("all")``)."""
        import pandas as pd

        return pd.DataFrame(self.long_rows(), columns=list(LONG_COLUMNS))

    table = renamed("table", "to_pandas(quantity)", lambda self, *a, **k: self.to_pandas(*a, **k))
    table_text = renamed("table_text", "to_text(quantity)", lambda self, *a, **k: self.to_text(*a, **k))
    to_frame = renamed("to_frame", 'to_pandas("all")', lambda self: self.to_pandas("all"))
    static_frame = renamed("static_frame", "preloads[run].to_pandas()",
                           lambda self, run=None: self.preloads[self.run(run).name].to_pandas())

    def to_dict(self) -> dict[str, Any]:
        """The answers as JSON-ready data (no time histories)."""
        runs = []
        for run in self.runs:
            runs.append({
                "name": run.name, "frequency_hz": run.frequency_hz,
                "excitation_amplitude_n": run.excitation_amplitude,
                "pylon": _direction_answers(run.pylon_amplitude, run.excitation_amplitude),
                "hinges": {name: _direction_answers(a, run.excitation_amplitude)
                           for name, a in run.hinge_amplitudes.items()},
                "pylon_hinges": list(run.pylon_hinges),
                "truncation_error": None if run.truncation_error is None else
                dict(zip(DIRECTIONS, map(float, run.truncation_error), strict=True)),
                "steady": run.steady, "steady_change": run.steady_change, "warnings": list(run.warnings),
                "static_hinge_forces_n": None if run.preload is None else
                {name: list(map(float, f)) for name, f in run.preload.hinge_forces.items()},
                "model_card": None if run.model_card is None else run.model_card.to_dict(),
            })
        return {"case": self.case_name, "runs": runs}

    def to_json(self, **kwargs) -> str:
        """:meth:`to_dict` as JSON text (keyword arguments go to json.dumps)."""
        return json.dumps(self.to_dict(), **kwargs)

    def plot_time_histories(self, run: str | None = None, locations=(PYLON_SUM,)):
        """Force histories of a run per direction, with the measured window shaded.

        Parameters
        ----------
        run : str, optional
            Run name (default: the first).
        locations : sequence of str
            Hinge names and/or ``"pylon sum"``.

        Returns
        -------
        matplotlib.figure.Figure
        """
        import matplotlib.pyplot as plt

        result = self.run(run)
        if not result.has_histories:
            raise ValueError(f"run {result.name!r} was answered in the frequency domain: it has no force histories "
                             f"(ask for the time domain: method 'time')")
        histories = {**result.hinge_histories, PYLON_SUM: result.pylon_history}
        fig, axes = plt.subplots(4, 1, sharex=True, figsize=(9, 8), constrained_layout=True)
        t = result.time
        for i, axis in enumerate(DIRECTIONS):
            for location in locations:
                axes[i].plot(t, histories[location][:, i], lw=0.7, label=location)
            axes[i].axvspan(t[result.window][0], t[result.window][-1], color="0.9")
            axes[i].set_ylabel(f"F{axis} N")
        for i, axis in enumerate(DIRECTIONS):
            axes[3].plot(t, result.excitation_history[:, i], lw=0.7, label=f"excitation {axis}")
        axes[3].set_ylabel("excitation N")
        axes[3].set_xlabel("time s")
        axes[0].legend(loc="upper right", fontsize="small")
        axes[3].legend(loc="upper right", fontsize="small")
        fig.suptitle(f"{self.case_name}: {result.name} ({result.frequency_hz:g} Hz); measured window shaded")
        return fig

    def plot_spectra(self, run: str | None = None, locations=(PYLON_SUM,)):
        """Amplitude spectra of the measured window per direction (log scale).

        Returns
        -------
        matplotlib.figure.Figure
        """
        import matplotlib.pyplot as plt

        from workbook.answers.amplitude import amplitude_spectrum

        result = self.run(run)
        histories = {**result.hinge_histories, PYLON_SUM: result.pylon_history}
        window = result.window
        fig, axes = plt.subplots(3, 1, sharex=True, figsize=(9, 7), constrained_layout=True)
        for i, axis in enumerate(DIRECTIONS):
            for location in locations:
                frequencies, amplitudes = amplitude_spectrum(result.time[window], histories[location][window, i])
                axes[i].semilogy(frequencies, np.maximum(amplitudes, 1e-12), lw=0.8, label=location)
            axes[i].axvline(result.frequency_hz, color="0.6", ls="--", lw=0.8)
            axes[i].set_ylabel(f"|F{axis}| N")
            axes[i].set_xlim(0, 4 * result.frequency_hz)
        axes[-1].set_xlabel("frequency Hz")
        axes[0].legend(loc="upper right", fontsize="small")
        fig.suptitle(f"{self.case_name}: {result.name}, spectrum of the measured window")
        return fig

    def plot_efficiency(self):
        """Bar chart of the pylon isolation efficiency per run and direction.

        Returns
        -------
        matplotlib.figure.Figure
        """
        import matplotlib.pyplot as plt

        fig, ax = plt.subplots(figsize=(7, 4), constrained_layout=True)
        self.draw_efficiency(ax)
        return fig

    def draw_efficiency(self, ax) -> None:
        """Draw :meth:`plot_efficiency`'s bar chart on the matplotlib axes *ax*."""
        rows, _ = self._table_rows("efficiency")
        width = 0.8 / len(DIRECTIONS)
        positions = np.arange(len(rows))
        for i, axis in enumerate(DIRECTIONS):
            bars = ax.bar(positions + (i - 1) * width, [values[1 + i] for values in rows.values()], width, label=axis)
            ax.bar_label(bars, fmt="%.1f", fontsize="small")
        ax.set_xticks(positions, [f"{name}\n{values[0]:g} Hz" for name, values in rows.items()])
        ax.set_ylabel("isolation efficiency %")
        ax.legend(title="direction")
        ax.set_title(f"{self.case_name}: pylon isolation efficiency", y=1.0)   # placed, not searched for


def _direction_answers(amplitude: np.ndarray, reference: float) -> dict[str, dict[str, float | None]]:
    t = transmissibility(amplitude, reference)
    answers = {}
    for axis, a, ti in zip(DIRECTIONS, amplitude, t, strict=True):
        db = float(level_db(ti))
        answers[axis] = {"amplitude_n": float(a), "transmissibility": float(ti),
                         "efficiency_pct": float(efficiency(ti)), "db": db if np.isfinite(db) else None}
    return answers
