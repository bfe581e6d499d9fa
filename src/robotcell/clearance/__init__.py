"""Clearance: the smallest distance between a robot's links and everything else in the cell.

A robot's links are capsules around the skeleton of its DH model (:mod:`.skeleton`), the tool a
capsule from the flange to the TCP; the cell's parts (fixtures, the positioner's plate, a
workpiece) are boxes, cylinders, spheres or capsules attached to the cell's frames
(:mod:`.bodies`). The distance between two shapes is computed by the collision library coal
(the successor of hpp-fcl, `pip install robotcell[clearance]`); :mod:`.distance` only chooses
which pairs to ask it about. :func:`clearance` checks the joint values of one program point by
point, with its segments interpolated as the controller moves (:mod:`.path`);
:func:`clearance_between` the robots of a cell against each other and the parts (:mod:`.robots`).

Lengths in metres, angles in radians (docs/conventions.md); docs/clearance.md for the model and
its limits.
"""

from robotcell.clearance.bodies import Body, read_bodies
from robotcell.clearance.distance import Clearance
from robotcell.clearance.path import clearance
from robotcell.clearance.robots import clearance_between
from robotcell.clearance.skeleton import LinkModel, link_segments

__all__ = ["Body", "Clearance", "LinkModel", "clearance", "clearance_between", "link_segments",
           "read_bodies"]
