"""crankmodal: structural dynamics of crank-linkage machines.

Stages (one subpackage each) hand plain data to each other:
parameters -> geometry -> mesh -> matrices -> modes -> reduced body -> dynamics -> report.
Heavy dependencies (gmsh, scikit-fem, pyvista) are imported inside the stage that uses them,
so ``import crankmodal`` stays light.

The public Python API is importable from the package itself (``from crankmodal import Part,
assemble, solve_modes``). The names are resolved lazily (PEP 562 module ``__getattr__``): each
is imported from its home module on first access, so ``import crankmodal`` loads none of
gmsh, scikit-fem, pyvista or matplotlib. The README's "Python API" section shows every stage.
"""

from importlib import import_module
from importlib.metadata import PackageNotFoundError
from importlib.metadata import version as _version

try:
    __version__ = _version("crankmodal")
except PackageNotFoundError:  # running from a source tree without install
    __version__ = "0.0.0+local"

#: public name -> (home module, attribute there). Grouped by stage, in data-flow order.
_EXPORTS: dict[str, tuple[str, str]] = {
    # scenes and the runner (what the CLI does, from Python)
    "Scene": ("crankmodal.scene", "Scene"),
    "load_scene": ("crankmodal.scene", "load_scene"),
    "scene_from_dict": ("crankmodal.scene", "scene_from_dict"),
    "check_scene": ("crankmodal.runner", "check"),
    "run_scene": ("crankmodal.runner", "run"),
    "list_machines": ("crankmodal.resources", "list_machines"),
    "scene_path": ("crankmodal.resources", "scene_path"),
    "load_machine": ("crankmodal.resources", "load_machine"),
    # errors
    "CrankmodalError": ("crankmodal.errors", "CrankmodalError"),
    "SceneError": ("crankmodal.errors", "SceneError"),
    "InputFileError": ("crankmodal.errors", "InputFileError"),
    "FileMemberError": ("crankmodal.errors", "FileMemberError"),
    "OutputError": ("crankmodal.errors", "OutputError"),
    "GeometryError": ("crankmodal.errors", "GeometryError"),
    "NumericalError": ("crankmodal.errors", "NumericalError"),
    "ParameterError": ("crankmodal.errors", "ParameterError"),
    # geometry -> Part
    "Part": ("crankmodal.part", "Part"),
    "Region": ("crankmodal.part", "Region"),
    "MassProperties": ("crankmodal.part", "MassProperties"),
    "CylindricalSurface": ("crankmodal.part", "CylindricalSurface"),
    "CrankshaftParams": ("crankmodal.geometry.params", "CrankshaftParams"),
    "ConrodParams": ("crankmodal.geometry.params", "ConrodParams"),
    "params_from_dict": ("crankmodal.geometry.params", "params_from_dict"),
    "MeshSettings": ("crankmodal.geometry.mesh", "MeshSettings"),
    "build_part": ("crankmodal.geometry.build", "build_part"),
    "import_mesh": ("crankmodal.geometry.importers", "import_mesh"),
    "import_cad": ("crankmodal.geometry.importers", "import_cad"),
    # FE: material, model, supports, loads, modes, static
    "Material": ("crankmodal.fem.materials", "Material"),
    "material": ("crankmodal.fem.materials", "material"),
    "FEModel": ("crankmodal.fem.assembly", "FEModel"),
    "assemble": ("crankmodal.fem.assembly", "assemble"),
    "mass_properties": ("crankmodal.fem.assembly", "mass_properties"),
    "Support": ("crankmodal.fem.supports", "Support"),
    "select_supports": ("crankmodal.fem.supports", "select_supports"),
    "Load": ("crankmodal.fem.loads", "Load"),
    "pressure_load": ("crankmodal.fem.loads", "pressure_load"),
    "traction_force": ("crankmodal.fem.loads", "traction_force"),
    "remote_force": ("crankmodal.fem.loads", "remote_force"),
    "bearing_load": ("crankmodal.fem.loads", "bearing_load"),
    "Modes": ("crankmodal.fem.modal", "Modes"),
    "solve_modes": ("crankmodal.fem.modal", "solve_modes"),
    "StaticResult": ("crankmodal.fem.static", "StaticResult"),
    "solve_static": ("crankmodal.fem.static", "solve_static"),
    # reduction -> reduced body (.npz)
    "Interface": ("crankmodal.reduction.interfaces", "Interface"),
    "make_interfaces": ("crankmodal.reduction.interfaces", "make_interfaces"),
    "reduce_body": ("crankmodal.reduction.reduce", "reduce_body"),
    "ReducedBody": ("crankmodal.reduction.flexbody", "FlexibleBody"),
    "save_flexbody": ("crankmodal.reduction.io", "save_flexbody"),
    "load_flexbody": ("crankmodal.reduction.io", "load_flexbody"),
    # torsion
    "TorsionalChain": ("crankmodal.torsion.chain", "TorsionalChain"),
    "ChainModes": ("crankmodal.torsion.chain", "ChainModes"),
    "exact_modes": ("crankmodal.torsion.chain", "exact_modes"),
    "HolzerResult": ("crankmodal.torsion.holzer", "HolzerResult"),
    "holzer": ("crankmodal.torsion.holzer", "holzer"),
    "TwoRotorResult": ("crankmodal.torsion.two_rotor", "TwoRotorResult"),
    "two_rotor": ("crankmodal.torsion.two_rotor", "two_rotor"),
    "reduce_to_two_rotors": ("crankmodal.torsion.two_rotor", "reduce_to_two_rotors"),
    "CrankModel": ("crankmodal.torsion.crank_model", "CrankModel"),
    "crank_model": ("crankmodal.torsion.crank_model", "crank_model"),
    "CriticalSpeeds": ("crankmodal.torsion.critical_speeds", "CriticalSpeeds"),
    "critical_speeds": ("crankmodal.torsion.critical_speeds", "critical_speeds"),
    # dynamics: bodies, joints, systems, mechanisms, runs
    "RigidBody": ("crankmodal.dynamics.model.bodies", "RigidBody"),
    "Ground": ("crankmodal.dynamics.model.bodies", "Ground"),
    "FlexibleBody": ("crankmodal.dynamics.flexible.body", "FlexibleBody"),
    "load_flexible_body": ("crankmodal.dynamics.flexible.body", "load_flexible_body"),
    "crank_body": ("crankmodal.dynamics.flexible.build", "crank_body"),
    "rod_body": ("crankmodal.dynamics.flexible.build", "rod_body"),
    "link_body": ("crankmodal.dynamics.flexible.build", "link_body"),
    "rigid_twin": ("crankmodal.dynamics.flexible.build", "rigid_twin"),
    "Revolute": ("crankmodal.dynamics.model.joints", "Revolute"),
    "Prismatic": ("crankmodal.dynamics.model.joints", "Prismatic"),
    "ClearanceJoint": ("crankmodal.dynamics.model.clearance", "ClearanceJoint"),
    "ClearanceSpec": ("crankmodal.dynamics.model.clearance", "ClearanceSpec"),
    "NormalLaw": ("crankmodal.dynamics.laws.objects", "NormalLaw"),
    "FrictionLaw": ("crankmodal.dynamics.laws.objects", "FrictionLaw"),
    "make_law": ("crankmodal.dynamics.laws.objects", "make_law"),
    "make_friction": ("crankmodal.dynamics.laws.objects", "make_friction"),
    "Multibody": ("crankmodal.dynamics.model.system", "Multibody"),
    "Cylinder": ("crankmodal.dynamics.model.mechanisms", "Cylinder"),
    "Mechanism": ("crankmodal.dynamics.model.mechanisms", "Mechanism"),
    "crank_train": ("crankmodal.dynamics.model.mechanisms", "crank_train"),
    "four_bar": ("crankmodal.dynamics.model.mechanisms", "four_bar"),
    "SolverSettings": ("crankmodal.dynamics.run.integrate", "SolverSettings"),
    "integrate": ("crankmodal.dynamics.run.integrate", "integrate"),
    "History": ("crankmodal.dynamics.results.history", "History"),
    "DynamicsResult": ("crankmodal.dynamics.results.result", "DynamicsResult"),
    "simulate": ("crankmodal.dynamics.run.simulate", "simulate"),
    "quasi_static_start": ("crankmodal.dynamics.flexible.initial", "quasi_static_start"),
    # multi-throw crank trains: the machine's arrangement, a motor through a coupling
    "Arrangement": ("crankmodal.mechanism.arrangement", "Arrangement"),
    "arrangement_of_machine": ("crankmodal.mechanism.arrangement", "arrangement_of_machine"),
    "MotorDrive": ("crankmodal.dynamics.model.drive", "MotorDrive"),
    "TorsionalCoupling": ("crankmodal.dynamics.model.loads", "TorsionalCoupling"),
}

# the same names as _EXPORTS (a literal list, for static tools); tests/test_api.py checks it
__all__ = [
    "Arrangement",
    "ChainModes",
    "ClearanceJoint",
    "ClearanceSpec",
    "ConrodParams",
    "CrankModel",
    "CrankmodalError",
    "CrankshaftParams",
    "CriticalSpeeds",
    "Cylinder",
    "CylindricalSurface",
    "DynamicsResult",
    "FEModel",
    "FileMemberError",
    "FlexibleBody",
    "FrictionLaw",
    "GeometryError",
    "Ground",
    "History",
    "HolzerResult",
    "InputFileError",
    "Interface",
    "Load",
    "MassProperties",
    "Material",
    "Mechanism",
    "MeshSettings",
    "Modes",
    "MotorDrive",
    "Multibody",
    "NormalLaw",
    "NumericalError",
    "OutputError",
    "ParameterError",
    "Part",
    "Prismatic",
    "ReducedBody",
    "Region",
    "Revolute",
    "RigidBody",
    "Scene",
    "SceneError",
    "SolverSettings",
    "StaticResult",
    "Support",
    "TorsionalChain",
    "TorsionalCoupling",
    "TwoRotorResult",
    "__version__",
    "arrangement_of_machine",
    "assemble",
    "bearing_load",
    "build_part",
    "check_scene",
    "crank_body",
    "crank_model",
    "crank_train",
    "critical_speeds",
    "exact_modes",
    "four_bar",
    "holzer",
    "import_cad",
    "import_mesh",
    "integrate",
    "link_body",
    "list_machines",
    "load_flexbody",
    "load_flexible_body",
    "load_machine",
    "load_scene",
    "make_friction",
    "make_interfaces",
    "make_law",
    "mass_properties",
    "material",
    "params_from_dict",
    "pressure_load",
    "quasi_static_start",
    "reduce_body",
    "reduce_to_two_rotors",
    "remote_force",
    "rigid_twin",
    "rod_body",
    "run_scene",
    "save_flexbody",
    "scene_from_dict",
    "scene_path",
    "select_supports",
    "simulate",
    "solve_modes",
    "solve_static",
    "traction_force",
    "two_rotor",
]


def __getattr__(name: str):
    """Import a public name from its home module on first access (PEP 562)."""
    try:
        module, attr = _EXPORTS[name]
    except KeyError:
        # a subpackage or module not imported yet (``crankmodal.dynamics``), as after an import
        from importlib.util import find_spec

        if not name.startswith("_") and find_spec(f"{__name__}.{name}") is not None:
            return import_module(f"{__name__}.{name}")
        raise AttributeError(f"module 'crankmodal' has no attribute {name!r}") from None
    value = getattr(import_module(module), attr)
    globals()[name] = value  # later accesses skip this function
    return value


def __dir__() -> list[str]:
    return sorted(set(globals()) | set(_EXPORTS))
