"""stickslip: nonlinear vibration of assemblies with friction joints.

Harmonic balance with alternating frequency/time evaluation of the joints, condensation and
pseudo-arclength continuation (the Rust library), driven from Python:

    import stickslip
    study = stickslip.Study.from_toml("examples/jenkins-1dof/study.toml")
    results = study.run()
    frame = results.to_pandas()          # the columns of the command line's frf.csv

Parameter studies (grids, Latin hypercubes) run serially, on local processes or on a Dask
cluster: see :func:`stickslip.run_parameters`. Units are SI, frequencies in Hz.
"""

from ._stickslip import (
    SUMMARY_COLUMNS,
    Error,
    InputError,
    ParamError,
    SolveError,
    StudyError,
    __version__,
    extract,
    modes,
    reduce,
)
from ._study import Backbone, Results, Study
from .params import ParamResults, design, run_parameters

__all__ = [
    "Backbone",
    "Error",
    "InputError",
    "ParamError",
    "ParamResults",
    "Results",
    "SUMMARY_COLUMNS",
    "SolveError",
    "Study",
    "StudyError",
    "__version__",
    "design",
    "extract",
    "modes",
    "reduce",
    "run_parameters",
]
