"""Studies: whole analyses that combine derivation and solver.

* ``reproduce.py`` -- ``gearsym reproduce``, the reference study's analyses;
* ``report.py`` -- its comparison report; ``cases.py`` -- its cases and resolutions;
* ``robustness.py`` -- the extremes matrix of every back end (``docs/robustness.md``).
"""
