"""Named choices and defaults that the command line shows before it loads the library.

`evclust --help` builds every verb's parser; keeping these here (no imports) lets it do so
without numpy, numba, OpenCV or matplotlib. The modules that use them import them from here.
"""

DEFAULT_GATE_PX = 30.0  # largest centre distance of a track-object match, px (docs/METRICS.md)

# The generalization suite's splits: parameters are chosen on "tuning", figures reported on "test".
SPLITS = {"tuning": tuple(range(32)), "test": tuple(range(1000, 1032))}

PLOT_KINDS = ("velocity", "colour", "scatter")
PLOT_AXES = ("index", "time")

TRACK_MODELS = ("float", "fixed", "rtl")  # evclust.run.MODELS builds them
SIMULATORS = ("icarus", "verilator")  # evclust.rtl.cosim runs the RTL under them
