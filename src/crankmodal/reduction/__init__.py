"""Craig–Bampton reduction of a part to a flexible body for the dynamics stage.

Modules, one concept each:

- :mod:`.interfaces` -- interface nodes at the exact bore centres, tied rigidly (RBE2-like, a
  sparse elimination) or by a distributing coupling (RBE3-like, six sparse constraint rows);
- :mod:`.craig_bampton` -- constraint modes and fixed-interface modes from one factorisation,
  reduced K and M;
- :mod:`.orthonormal` -- M-orthonormal, K-diagonal modal coordinates, rigid-body modes, mass
  properties;
- :mod:`.flexbody` -- the :class:`~.flexbody.FlexibleBody` (reduced matrices, interface map,
  mass properties, Shabana's inertia invariants);
- :mod:`.stress_modes` -- nodal stresses of all modes from one vectorised recovery;
- :mod:`.io` -- the documented ``.npz`` file;
- :mod:`.reduce` -- model → body in one call; :mod:`.stage` -- the ``[reduction]`` section.

Only numpy and scipy are imported at module level; scikit-fem only by :mod:`.stress_modes`.
"""
