//! Plots of results (plotters): FRFs of all levels, harmonics, hysteresis loops.
