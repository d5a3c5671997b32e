"""gearsym.benchmarks -- speed and accuracy measurements, each writing a Markdown table.

* ``performance`` -- speed against accuracy of every integration back end (``gearsym bench``
  or ``python -m gearsym.benchmarks.performance``); writes ``performance.md`` and
  ``performance-pareto.png`` to an output folder, or to the checkout's ``docs/`` with
  ``--docs``; its sections live in ``baseline`` (the reference model, the plain baseline
  and the hand-written C), ``backends`` (sections 1-5) and ``sections`` (the appended
  sections and the floors table);
* ``peers`` -- the 400-point sweep by the engine, the hand-written lockstep reference and
  JAX + diffrax (optional: skipped with the reason when absent), at equal accuracy, in one
  run; ``rhs_cost`` -- floating-point operations per point and evaluation of the generated
  batched right-hand side, with and without shared parameters;
* ``floors`` -- this checkout against another one (``--before DIR``), alternating fresh
  processes: the speed floors of the engine and whether the results are the same;
* ``verdicts`` -- the verdict benchmark of issue 27: regime-map verdicts at default
  settings against 10,000-period reference runs classified by ``_verdicts_reference``
  (its own code: no verdict module of the solver); writes ``docs/verdicts.md`` and
  ``docs/verdicts.json``; ``verdict_cost`` -- what the verdicts cost: the 400-point sweep and
  ``gearsym reproduce``, this checkout against another (``--before DIR``);
* ``robustness`` -- the extremes matrix, every case with every back end
  (``python -m gearsym.benchmarks.robustness``; writes ``docs/robustness.md``, needs the
  checkout, whose tests list the bad-input cases);
* ``deadzone_multipliers`` -- Floquet multipliers of a dead-zone orbit against the
  tolerance (``python -m gearsym.benchmarks.deadzone_multipliers``; writes
  ``docs/deadzone-multipliers.md``);
* ``lockstep_reference.c`` -- the hand-written vectorised lockstep DOP853 in C that
  ``performance`` times the compiled back end against (shipped as package data);
* ``_output`` -- output folders: the checkout's ``docs/``, the writability check made
  before a long run, and the one-line failure of the scripts.

Each module also runs as a script from a checkout: ``python benchmarks/<name>.py``.
"""
