"""Studies and their results (the native study wrapped so that it pickles and reads well)."""

from __future__ import annotations

import os

import numpy as np

from . import _stickslip
from ._stickslip import SolveError


class Study:
    """A validated study: build it with :meth:`from_toml` or :meth:`from_dict`."""

    def __init__(self, native: _stickslip.Study):
        self._native = native

    @classmethod
    def from_toml(cls, path) -> "Study":
        """Read and validate a study file (errors name the file, line, column and key)."""
        return cls(_stickslip.Study.from_toml(os.fspath(path)))

    @classmethod
    def from_dict(cls, d: dict, path=None) -> "Study":
        """Validate a study given as a dict shaped like the file, e.g.
        ``{"model": {...}, "joint": [{...}], "sweep": {"start_hz": 150.0, "end_hz": 350.0}}``.
        ``path`` names it in errors and anchors relative file paths (``<dict>`` in the
        current folder by default)."""
        return cls(_stickslip.Study.from_dict(d, None if path is None else os.fspath(path)))

    def to_dict(self) -> dict:
        """The study as a dict (a copy)."""
        return self._native.to_dict()

    def to_toml(self) -> str:
        return self._native.to_toml()

    @property
    def path(self) -> str:
        return self._native.path

    @property
    def levels(self) -> list:
        """Force levels (N)."""
        return self._native.levels

    def run(self, progress=None, strict: bool = False) -> "Results":
        """Sweep the band at every force level (levels in parallel). ``progress(level_n, fraction_done,
        frequency_hz)`` is called after each converged point (e.g. to move a tqdm bar). A
        level whose branch does not cross the band is kept and marked (``Results.levels``);
        with ``strict=True`` it raises :class:`SolveError` as the command line does."""
        results = Results(self._native._run(progress))
        if strict:
            results.check()
        return results

    def timesim(self, frequency_hz: float, level_n: float, steps_per_period: int = 256,
                tolerance: float = 1e-6, max_periods: int = 5000) -> dict:
        """Steady-state time integration at one frequency and force level (one period of the
        outputs and of the joints, the periods needed, the energy dissipated per cycle)."""
        return self._native.timesim(float(frequency_hz), float(level_n), int(steps_per_period),
                                    float(tolerance), int(max_periods))

    def nonlinear_mode(self, progress=None, strict: bool = False) -> "Backbone":
        """The backbone of the study's ``[nonlinear_mode]`` (damped nonlinear mode, EPMC):
        frequency, damping ratio, energy, stick fractions and harmonics against the modal
        amplitude, as the command line's ``backbone.csv``. ``progress(modal_amplitude)`` is
        called after each converged point. A branch that stops short is kept and marked
        (``Backbone.complete``, ``Backbone.ending``); with ``strict=True`` it raises
        :class:`SolveError` as the command line does."""
        backbone = Backbone(self._native.nonlinear_mode(progress))
        if strict and not backbone.complete:
            raise SolveError(f"nonlinear mode: the branch {backbone.ending} (its points are kept)")
        return backbone

    def __reduce__(self):
        # Studies travel to worker processes as their dict and path.
        return (_from_dict_and_path, (self.to_dict(), self.path))

    def __repr__(self) -> str:
        return f"Study({self.path!r})"


def _from_dict_and_path(d, path):
    return Study.from_dict(d, path)


class _Table:
    """A command line table as NumPy: ``columns`` (units in the names) and ``table``, one row
    per point."""

    columns: list
    table: np.ndarray

    def column(self, name: str) -> np.ndarray:
        try:
            return self.table[:, self.columns.index(name)]
        except ValueError:
            raise KeyError(f"no column {name!r}; columns are: {', '.join(self.columns)}") from None

    def __len__(self) -> int:
        return self.table.shape[0]


class Results(_Table):
    """The converged points of every level of a run: the numbers of the command line's
    ``frf.csv`` (same columns, units in the names) as a NumPy table."""

    def __init__(self, data: dict):
        self.columns: list = list(data["columns"])
        self.table: np.ndarray = data["table"]
        #: Per level: ``level_N``, ``points``, ``complete``, ``ending`` (why the branch ended),
        #: ``newton_iterations``, ``evaluations``, and the wall clock (s) of its stages:
        #: ``sweep_s``, ``located_peaks_s``, ``located_bifurcations_s``.
        self.levels: list = data["levels"]
        self.outputs: list = data["outputs"]
        self.elements: list = data["elements"]
        self.harmonics: int = data["harmonics"]

    @property
    def frequency_hz(self) -> np.ndarray:
        return self.column("frequency_Hz")

    @property
    def level_n(self) -> np.ndarray:
        return self.column("level_N")

    @property
    def residual(self) -> np.ndarray:
        """Final Newton residual of each point, relative to the linear response at the band's
        start (the measure of the study's `tolerance`; docs/study-file.md)."""
        return self.column("residual_rel")

    def amplitudes(self, output: str) -> np.ndarray:
        """Amplitudes (m) of harmonics 0..N of an output, one row per point."""
        return np.stack([self.column(f"{output}_h{k}_amp_m") for k in range(self.harmonics + 1)], axis=1)

    def phases(self, output: str) -> np.ndarray:
        """Phases (rad) of harmonics 0..N of an output, one row per point."""
        return np.stack([self.column(f"{output}_h{k}_phase_rad") for k in range(self.harmonics + 1)], axis=1)

    def energy(self, element: str) -> np.ndarray:
        """Energy dissipated per cycle by a joint (J), one value per point."""
        return self.column(f"{element}_energy_J")

    def stick_fraction(self, element: str) -> np.ndarray:
        return self.column(f"{element}_stick_fraction")

    @property
    def input_energy(self) -> np.ndarray:
        """Work of the excitation per cycle (J), one value per point."""
        return self.column("input_energy_J")

    @property
    def viscous_energy(self) -> np.ndarray:
        """Energy dissipated per cycle by the viscous damping (J), one value per point: with the
        joints' `energy`, it balances `input_energy` at a converged point."""
        return self.column("viscous_energy_J")

    def level(self, index: int) -> "Results":
        """The points of one level (by its index in the study's levels)."""
        keep = self.level_n == self.levels[index]["level_N"]
        data = dict(columns=self.columns, table=self.table[keep], levels=[self.levels[index]],
                    outputs=self.outputs, elements=self.elements, harmonics=self.harmonics)
        return Results(data)

    @property
    def complete(self) -> bool:
        """Did every level's branch cross the whole band?"""
        return all(lv["complete"] for lv in self.levels)

    def check(self) -> None:
        """Raise :class:`SolveError` if a level did not cross the band (the command line's
        message)."""
        bad = [f"level {lv['level_N']} N {lv['ending']}" for lv in self.levels if not lv["complete"]]
        if bad:
            raise SolveError(f"{len(bad)} level(s) did not cross the band (their points are kept):\n  "
                             + "\n  ".join(bad))

    def to_pandas(self):
        """The table as a pandas DataFrame (Newton iterations as integers)."""
        import pandas as pd

        frame = pd.DataFrame(self.table, columns=self.columns)
        frame["newton_iterations"] = frame["newton_iterations"].astype("int64")
        return frame

    def __repr__(self) -> str:
        return (f"Results({len(self)} points, levels {[lv['level_N'] for lv in self.levels]} N, "
                f"outputs {self.outputs}, elements {self.elements})")


class Backbone(_Table):
    """A damped nonlinear mode: the numbers of the command line's ``backbone.csv`` (same
    columns, units in the names) as a NumPy table, one row per point."""

    def __init__(self, data: dict):
        self.columns: list = list(data["columns"])
        self.table: np.ndarray = data["table"]
        #: Folds in amplitude and branch points (``kind``, ``modal_amplitude_m_sqrtkg``,
        #: ``frequency_Hz``, ``damping_ratio``, ``located``), as ``backbone_bifurcations.csv``.
        self.bifurcations: list = data["bifurcations"]
        #: Whether the branch reached ``amplitude_end``; ``ending`` says why it ended.
        self.complete: bool = data["complete"]
        self.ending: str = data["ending"]
        self.notes: list = data["notes"]
        self.linear_frequency_hz: float = data["linear_frequency_Hz"]
        self.linear_damping_ratio: float = data["linear_damping_ratio"]

    @property
    def amplitude(self) -> np.ndarray:
        """Modal amplitude (m·√kg): the mass norm of harmonic 1 of the motion."""
        return self.column("modal_amplitude_m_sqrtkg")

    @property
    def frequency_hz(self) -> np.ndarray:
        return self.column("frequency_Hz")

    @property
    def damping_ratio(self) -> np.ndarray:
        return self.column("damping_ratio")

    def to_pandas(self):
        """The table as a pandas DataFrame."""
        import pandas as pd

        return pd.DataFrame(self.table, columns=self.columns)

    def __repr__(self) -> str:
        f = self.frequency_hz
        return (f"Backbone({len(self)} points, {f[0]:.4f} -> {f[-1]:.4f} Hz, "
                f"{'complete' if self.complete else 'incomplete: ' + self.ending})")
