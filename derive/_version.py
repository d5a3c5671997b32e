"""The generator's version (written into every input hash); imports nothing."""

__version__ = "0.1.0"

# The emitted module's format: bump it whenever the generated code changes for the same
# inputs (a new table, a new check), so that models derived into the cache before the
# change are derived again instead of being loaded stale.  2: parameter limits and the
# stiffness-sign check in parameters() (issue 14); 3: that check done once per harmonics;
# 4: STRUCTURE (the physical matrices for the modal analysis) and models on bearings;
# 5: PHYSICAL and the physical quantities evaluated in parameters() (issue 25); 6: the C
# text no longer names the model (models with the same equations share a library); 7:
# C_JACOBIAN, the Jacobian's nonzero entries in C (the monodromy in one run); 8: a scene's
# speed_rpm and torque_Nm_<gear> in [parameters] are its operating point (they were
# ignored: a model cached from such a scene ran at the topology's speed).
# ``gearsym derive --check`` names a generated file whose text changed while its inputs
# hash did not (derive/build.py), the sign that this number was not bumped.
EMITTED_FORMAT = 8
