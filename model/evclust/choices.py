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

# A stream without a frame period (a real event camera) takes the parameters' frame-based time
# constants at this period: 25 fps, near the geometric middle of the suite's 10-60 fps, so that
# no scene of it is more than a factor 2.5 away. A rule, not a fit: no split was looked at to pick
# it. What withholding the period costs on the suite: docs/GENERALIZATION.md.
FRAMELESS_PERIOD_US = 40_000.0
