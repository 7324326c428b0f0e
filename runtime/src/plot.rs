//! Plots (SVG/PNG) of simulation traces, with plotters.
