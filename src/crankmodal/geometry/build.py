"""Build, tag and mesh a part from parameters: the one call most users need."""

from __future__ import annotations

from ..part import Part
from .checks import check_conrod, check_crankshaft, check_fidelity
from .massprops import cad_mass_properties, compare, mesh_mass_properties
from .mesh import MeshSettings, check_size, detail_faces, generate, quality, set_sizes, to_meshio
from .params import ConrodParams, CrankshaftParams
from .regions import regions_from_mesh, tag_regions
from .session import gmsh_session, quiet_stdout


def _check_settings(settings: MeshSettings) -> None:
    """Refuse MeshSettings out of range with a ParameterError naming the field (``size``,
    ``order``, ``refine``)."""
    from .mesh import check_settings

    check_settings(settings)  # also refuses a settings that is no MeshSettings, or a text size


def mesh_tagged(gmsh, volumes: list, specs: list, settings: MeshSettings, refined=()):
    """Name the regions of the current (synchronised) model, mesh it and read it back.

    Returns
    -------
    mesh, regions, stats
        The meshio mesh, the named :class:`~crankmodal.part.Region` objects and the mesh
        statistics of :func:`~crankmodal.geometry.mesh.quality`.
    """
    volume = sum(gmsh.model.occ.getMass(3, v) for v in volumes)
    area = sum(gmsh.model.occ.getMass(2, s) for _, s in gmsh.model.getEntities(2))
    check_size(volume, area, settings)  # before gmsh meshes: an absurd size is refused at once
    tagged = tag_regions(gmsh, specs)
    gmsh.model.addPhysicalGroup(3, volumes, name="solid")
    set_sizes(gmsh, settings, list(refined))
    generate(gmsh, settings)
    mesh, index = to_meshio(gmsh)
    return mesh, regions_from_mesh(gmsh, tagged, specs, index), quality(gmsh, mesh)


def build_part(params: CrankshaftParams | ConrodParams, fidelity: str, settings: MeshSettings,
               name: str = "", step_file=None) -> Part:
    """Make, mesh and name a crankshaft or connecting rod.

    Parameters
    ----------
    params : CrankshaftParams or ConrodParams
        Checked here before gmsh runs.
    fidelity : str
        ``full``, ``dechamfered`` or ``simplified``.
    settings : MeshSettings
        Mesh size (m), order, refinement.
    name : str
        Part name (default: the parameter type).
    step_file : path, optional
        Also write the CAD solid to this STEP file (metres).

    Returns
    -------
    Part
        With regions, CAD mass properties, and in ``quality`` the mesh statistics and the
        mesh-vs-CAD mass-property differences (``mass_check``).

    Raises
    ------
    ParameterError
        Naming ``fidelity`` (unknown) or the settings' ``size``, ``order``, ``refine`` out of
        range; :class:`~crankmodal.geometry.mesh.MeshSizeError` (naming ``size``) when the size
        makes more tetrahedra than ``settings.max_elements``.
    GeometryError
        Impossible parameters (named ``crankshaft.<name>`` / ``rod.<name>``) or a kernel failure.
    """
    check_fidelity(fidelity)
    _check_settings(settings)
    if isinstance(params, CrankshaftParams):
        check_crankshaft(params)
        from .crankshaft import build_crankshaft as builder
        kind = "crankshaft"
    else:
        check_conrod(params)
        from .conrod import build_conrod as builder
        kind = "rod"
    import time

    from ..progress import PhaseTimings

    described = {**params.to_dict(), "fidelity": fidelity, **settings.to_dict()}
    phases = PhaseTimings(f"geometry: {kind} ({fidelity})", 3)
    t0 = time.perf_counter()
    with gmsh_session(f"{kind} ({fidelity})", described) as gmsh:
        volumes, specs, detail = builder(gmsh, params, fidelity)
        cad = cad_mass_properties(gmsh, volumes)
        phases["cad_s"] = time.perf_counter() - t0
        if step_file is not None:
            gmsh.option.setString("Geometry.OCCTargetUnit", "M")  # the STEP file says metres
            with quiet_stdout():  # OpenCASCADE's STEP writer prints its statistics
                gmsh.write(str(step_file))
        refined = sorted(set(detail_faces(gmsh, detail["radius"])) | set(detail["faces"]))
        t0 = time.perf_counter()
        mesh, regions, stats = mesh_tagged(gmsh, volumes, specs, settings, refined)
        phases["mesh_s"] = time.perf_counter() - t0
    try:
        stats["mass_check"] = compare(cad, mesh_mass_properties(mesh.points, mesh.cells[0].data))
        phases["mass_check_s"] = 0.0
    except ValueError as exc:
        phases.close()
        from ..errors import GeometryError

        raise GeometryError(f"{kind} ({fidelity}): {exc}; parameters: {described}") from None
    return Part(name=name or kind, mesh=mesh, regions=regions, fidelity=fidelity,
                params={"part": kind, **params.to_dict(), "mesh": settings.to_dict()},
                cad_mass=cad, quality=stats)
