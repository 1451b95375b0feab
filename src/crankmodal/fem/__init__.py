"""Finite elements on a Part: K/M assembly, free and supported modes, static strength.

Modules (one concept each): :mod:`materials` (library), :mod:`assembly` (K, M on P1/P2 tets),
:mod:`solvers` (factorisation backends), :mod:`supports` (constraint elimination),
:mod:`modal` (shift-invert eigen solution and its checks), :mod:`classify` (mode names),
:mod:`loads` and :mod:`static` (strength), :mod:`convergence` (error against run time),
:mod:`vtu` (ParaView output). Nothing heavy is imported at package level.
"""
