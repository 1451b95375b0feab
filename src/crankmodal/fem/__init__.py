"""Finite elements on a Part: K/M assembly, free and supported modes, static strength.

Modules (one concept each): :mod:`materials` (library), :mod:`assembly` (K, M on P1/P2 tets),
:mod:`solvers` (factorisation backends), :mod:`supports` (constraint elimination),
:mod:`modal` (the modal solve: :mod:`modes` its result, :mod:`lanczos`,
:mod:`rigid_modes`, :mod:`modal_checks`, :mod:`dense_eigen`), :mod:`classify` (mode names),
:mod:`loads` and :mod:`static` (strength), :mod:`convergence` (error against run time),
:mod:`vtu` (ParaView output). Nothing heavy is imported at package level.
"""
