"""Rigid slider-crank mechanisms: kinematics, inertia forces, gas forces, friction, crank torque.

Sign conventions (one for the whole subpackage, after seed 000, Fig. 2):

* The plane of motion is x-y, with y along the axis of cylinder 1 and x to its right; z is the
  crank axis. Axial offsets ``b`` of the cylinders are z coordinates from the centre of symmetry.
* ``theta`` is the crank angle measured from +y towards +x; the crank turns in that sense at
  ``omega`` > 0. The crankpin direction is ``u(theta) = (sin theta, cos theta)``.
* ``phi`` (bank angle) is a cylinder axis measured from +y towards +x ("right of y positive").
  A cylinder's unit axis is ``e = (sin phi, cos phi)``, pointing from the crank to the head.
* ``psi = theta + gamma - phi`` is the crank angle of a cylinder from its own top dead centre,
  where ``gamma`` is the throw angle of its crankpin (0 when all rods share one pin).
* Piston displacement ``x`` is measured from top dead centre towards the crank (seed eq. 1), and
  so are velocity ``v``, acceleration ``a``, gas, friction and piston forces along the cylinder.
* Inertia forces are d'Alembert forces ``-m a`` as felt by the frame (seed Table 1): the
  reciprocating one of cylinder i is ``m r omega^2 (cos psi + lambda cos 2 psi) e``.
* ``crank_torque`` is the torque the rods exert on the crankshaft, positive in the sense of
  rotation: positive on average for an engine, negative for a compressor.
"""
