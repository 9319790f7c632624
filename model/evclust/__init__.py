"""evclust: colour event simulator, event-by-event clusterer, fixed-point model and RTL.

Data flows one way: scene -> simulator -> events -> clusterer -> tracks -> metrics -> report.
"""

__version__ = "0.1.0"
