"""A scene's operating point stated in the engineer's units (issue 25, point 1)."""

from __future__ import annotations

import math
from dataclasses import replace

from .topology import Operating

__all__ = ["SPEED", "TORQUE", "stated_physically"]

SPEED, TORQUE = "speed_rpm", "torque_Nm_"


def stated_physically(pt, parameters: dict, topology):
    """A scene's operating point stated in the engineer's units: ``speed_rpm`` (of the
    topology's operating gear, else the reference mesh's driver) instead of ``omega``, and
    ``torque_Nm_<gear>`` instead of ``[loads]``; each taken out of ``parameters`` into the
    topology the model is derived from (its ``[operating]`` speed, its ``[[torque]]``), as a
    topology derived on its own takes them.  Both forms of one quantity are refused, naming
    both keys."""
    physical = {
        k: parameters.pop(k) for k in list(parameters) if k == SPEED or k.startswith(TORQUE)
    }
    if not physical:
        return topology
    if SPEED in physical and "omega" in parameters:
        raise pt.error(SPEED, "stated beside omega, which states the speed too; keep one of them")
    gears = {g.id for g in topology.gears}
    torques = dict(topology.torques)
    for key, value in physical.items():
        if key.startswith(TORQUE):
            gear = key[len(TORQUE) :]
            if gear not in gears:
                raise pt.error(
                    key, f"names no gear of the topology; gears: {', '.join(sorted(gears))}"
                )
            torques[gear] = float(value)
    operating = topology.operating
    if SPEED in physical:
        speed = physical[SPEED]
        if not (math.isfinite(speed) and speed > 0):
            raise pt.error(SPEED, f"= {speed:g}: give a speed above 0 rpm")
        gear = operating.gear if operating is not None else topology.reference.driver
        damping = parameters.get("damping_ratio", operating.damping_ratio if operating else 0.0)
        operating = Operating(gear, speed * math.pi / 30.0, damping)
    return replace(topology, torques=torques, operating=operating)
