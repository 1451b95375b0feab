"""A modal report as one self-contained HTML file and a Markdown twin.

The report is a list of blocks — headings, paragraphs, tables, images — rendered twice: to HTML
with every image embedded as base64 (the file can be mailed on its own, no external links) and
to Markdown that links the PNGs next to it. :func:`modal_blocks` assembles the standard
content of a modal run (part and mesh, material, supports, modes, renders, MAC, measured
frequencies, timings, versions).
"""

from __future__ import annotations

import base64
import html
import re
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from .quantity import number, percent, quantity

_MIME = {".png": "image/png", ".gif": "image/gif", ".jpg": "image/jpeg", ".jpeg": "image/jpeg"}

_CSS = """
body{font-family:system-ui,-apple-system,Segoe UI,Helvetica,Arial,sans-serif;max-width:1100px;
margin:2em auto;padding:0 1em;color:#222;line-height:1.45}
h1{border-bottom:2px solid #335;padding-bottom:.2em}h2{margin-top:1.8em;color:#335}
h3{margin-top:1.2em;color:#446}
table{border-collapse:collapse;margin:.6em 0;font-size:.9em}
th,td{border:1px solid #bbb;padding:.25em .6em;text-align:left;vertical-align:top}
th{background:#eef}td.n{text-align:right;white-space:nowrap}
figure{margin:1em 0}img{max-width:100%;border:1px solid #ddd}
figcaption{font-size:.85em;color:#555}.note{color:#555;font-size:.9em}
"""


@dataclass
class Report:
    """Blocks of a report: ``(kind, ...)`` with kind ``h2``, ``p``, ``table``, ``img``."""

    title: str
    blocks: list = field(default_factory=list)

    def heading(self, text: str, level: int = 2):
        """A section (``level`` 2) or subsection (3) heading."""
        self.blocks.append((f"h{min(max(int(level), 2), 3)}", text))

    def paragraph(self, text: str):
        self.blocks.append(("p", text))

    def table(self, header: list, rows: list):
        self.blocks.append(("table", list(header), [list(r) for r in rows]))

    def image(self, path, caption: str = ""):
        self.blocks.append(("img", Path(path), caption))

    def to_html(self) -> str:
        """One HTML document; images inlined as data URIs."""
        out = ["<!DOCTYPE html>", "<html lang=\"en\"><head><meta charset=\"utf-8\">",
               f"<title>{html.escape(self.title)}</title><style>{_CSS}</style></head><body>",
               f"<h1>{html.escape(self.title)}</h1>"]
        for b in self.blocks:
            if b[0] in ("h2", "h3"):
                out.append(f"<{b[0]}>{html.escape(b[1])}</{b[0]}>")
            elif b[0] == "p":
                out.append(f"<p>{html.escape(b[1])}</p>")
            elif b[0] == "table":
                out.append("<table><thead><tr>" + "".join(f"<th>{html.escape(str(h))}</th>"
                                                          for h in b[1]) + "</tr></thead><tbody>")
                for r in b[2]:
                    out.append("<tr>" + "".join(_html_cell(_cell(c), first=k == 0)
                                                for k, c in enumerate(r)) + "</tr>")
                out.append("</tbody></table>")
            elif b[0] == "img":
                mime = _MIME.get(b[1].suffix.lower(), "application/octet-stream")
                data = base64.b64encode(b[1].read_bytes()).decode("ascii")
                out.append(f"<figure><img src=\"data:{mime};base64,{data}\" "
                           f"alt=\"{html.escape(b[2] or b[1].name)}\">"
                           f"<figcaption>{html.escape(b[2])}</figcaption></figure>")
        out.append("</body></html>")
        return "\n".join(out) + "\n"

    def to_markdown(self, relative_to: Path | None = None) -> str:
        """Markdown with images linked by file name (relative to ``relative_to``)."""
        out = [f"# {self.title}", ""]
        for b in self.blocks:
            if b[0] in ("h2", "h3"):
                out += ["#" * int(b[0][1]) + f" {b[1]}", ""]
            elif b[0] == "p":
                out += [b[1], ""]
            elif b[0] == "table":
                out.append("| " + " | ".join(str(h) for h in b[1]) + " |")
                out.append("|" + "---|" * len(b[1]))
                out += ["| " + " | ".join(_md_cell(_cell(c)) for c in r) + " |" for r in b[2]]
                out.append("")
            elif b[0] == "img":
                p = b[1]
                if relative_to is not None:
                    try:
                        p = p.resolve().relative_to(Path(relative_to).resolve())
                    except ValueError:
                        pass
                out += [f"![{b[2]}]({p.as_posix()})", ""]
        return "\n".join(out)


def _cell(c) -> str:
    """A table cell's text: a dash for a missing value, a plain number (never ``e+04``)."""
    if c is None:
        return "–"
    if isinstance(c, (float, np.floating)):
        return number(c)
    return str(c)


#: a short cell that starts with a number: a value, right-aligned in HTML so digits line up
#: (a sentence such as a summary starting with "4 cyl at ..." stays left-aligned and wraps)
_NUMERIC = re.compile(r"^[-+−±<>≈]?\s?\d")
_NUMERIC_MAX_CHARS = 32


def _html_cell(text: str, first: bool = False) -> str:
    """``<td>`` of a cell's text, escaped for HTML; values right-aligned, words (and the first
    column, which names the row: ``1st-order force``) left."""
    numeric = not first and len(text) <= _NUMERIC_MAX_CHARS and _NUMERIC.match(text)
    cls = ' class="n"' if numeric else ""
    return f"<td{cls}>{html.escape(text)}</td>"


def _md_cell(text: str) -> str:
    """A cell's text for a Markdown table: a literal bar would split the cell, so it is escaped
    there (and only there: HTML shows ``|F1|`` as it is)."""
    return text.replace("|", "\\|")


def versions() -> dict:
    """Installed versions of crankmodal and its numerical stack (no heavy imports)."""
    import platform
    from importlib.metadata import PackageNotFoundError, version

    out = {"python": platform.python_version()}
    for name in ("crankmodal", "numpy", "scipy", "scikit-fem", "gmsh", "meshio", "pyvista",
                 "vtk", "matplotlib"):
        try:
            out[name] = version(name)
        except PackageNotFoundError:
            out[name] = "not installed"
    return out


EFFECTIVE_MASS_KEYS = ("x_kg", "y_kg", "z_kg", "rx_kgm2", "ry_kgm2", "rz_kgm2")
EFFECTIVE_MASS_HEADER = ["m_eff x, kg", "m_eff y, kg", "m_eff z, kg", "J_eff x, kg m²",
                         "J_eff y, kg m²", "J_eff z, kg m²"]
MODE_HEADER = ["mode", "frequency, Hz", "class", *EFFECTIVE_MASS_HEADER, "residual"]


def carries_effective_mass(modal: dict) -> bool:
    """Whether any elastic mode has an effective mass above round-off (1e-9 of the total).

    A free-free part's elastic modes carry none: its rigid-body modes take the whole mass, so
    the effective-mass columns would be zeros only."""
    em = modal.get("effective_mass") or {}
    floor = 1e-9 * modal.get("total_mass_kg", 0.0)
    return any(abs(v) > floor for c in EFFECTIVE_MASS_KEYS for v in em.get(c, ()))


def mode_rows(modal: dict, effective_mass: bool = True) -> list[list]:
    """Table rows from a ``[modal]`` results dict: frequency, class, effective masses (with
    ``effective_mass``; see :data:`MODE_HEADER`), residual."""
    f = modal["frequencies_hz"]
    classes = modal.get("classes") or [None] * len(f)
    em = modal.get("effective_mass", {})
    res = modal.get("residuals") or [None] * len(f)
    # effective masses below 1e-9 of the total are round-off (free-free elastic modes carry none)
    floor = 1e-9 * modal.get("total_mass_kg", 0.0)

    def fmt(v):
        return "0" if abs(v) <= floor else number(v, 3)

    rows = []
    for k in range(len(f)):
        rows.append([k + 1, f"{f[k]:.2f}", classes[k]]
                    + ([fmt(em[c][k]) if c in em else None for c in EFFECTIVE_MASS_KEYS]
                       if effective_mass else [])
                    + [number(res[k], 2) if res[k] is not None else None])
    return rows


def measured_rows(frequencies_hz, measured_hz, tolerance: float) -> list[list]:
    """Rows: mode, measured Hz, computed Hz, difference (computed vs measured), and the verdict
    against ``tolerance`` (admissible ``|f - f_measured| / f_measured``)."""
    from .testing import compare_frequencies

    tol = percent(tolerance)
    return [[r["mode"], f"{r['expected_hz']:.1f}",
             None if r["computed_hz"] is None else f"{r['computed_hz']:.1f}",
             None if r["rel_error"] is None else percent(r["rel_error"], sign=True),
             ("not computed" if r["computed_hz"] is None
              else f"{'within' if r['ok'] else 'OUTSIDE'} ±{tol}")]
            for r in compare_frequencies(frequencies_hz, measured_hz, rtol=tolerance)]


MEASURED_HEADER = ["mode", "measured, Hz", "computed, Hz", "difference", "verdict"]


def modal_blocks(report: Report, *, geometry: dict, material: dict, modal: dict,
                 renders: dict | None = None, mac: dict | None = None,
                 measured_hz=None, tolerance: float = 0.05, timings: dict | None = None,
                 extra_images=(), level: int = 2, versions_table: bool = True) -> Report:
    """Fill a report with the standard modal content.

    Parameters
    ----------
    geometry, material, modal : dict
        The stages' results dicts (``[geometry]``, ``[material]``, ``[modal]``).
    renders : dict, optional
        From :func:`crankmodal.report.render.render_modes` (``modes``, ``sheet``, ``gifs``).
    mac : dict, optional
        ``matrix``, ``image``, ``source``, ``pairs``.
    measured_hz : sequence, optional
        Hz by mode (None where nothing was measured).
    tolerance : float
        Admissible relative difference from the measured frequencies (the verdict column).
    timings : dict, optional
        Section -> wall time, s.
    extra_images : iterable of (path, caption)
    level : int
        Heading level of its sections (2, or 3 inside a scene report's section).
    versions_table : bool
        End with the installed versions (a scene report puts them at its own end).
    """
    def heading(text):
        report.heading(text, level)

    q = geometry.get("quality") or {}
    heading("Part and mesh")
    rows = [["part", geometry.get("name")], ["fidelity", geometry.get("fidelity")],
            ["element order", f"P{geometry.get('element_order')}"],
            ["elements", geometry.get("n_elements")], ["nodes", geometry.get("n_nodes")],
            ["free DOF solved", modal.get("n_dofs")]]
    if q.get("measure"):
        rows.append([f"quality ({q['measure']}) min / mean", f"{q['min']:.3f} / {q['mean']:.3f}"])
    if "mass_kg" in modal:
        rows.append(["mass from the mesh, kg", f"{modal['mass_kg']:.4g}"])
    if modal.get("mass_vs_cad") is not None:
        rows.append(["mesh mass vs CAD", f"{100 * modal['mass_vs_cad']:+.3f} %"])
    report.table(["quantity", "value"], rows)
    heading("Material")
    E = material.get("E_pa", material.get("E"))
    rho = material.get("rho_kg_m3", material.get("rho"))
    mrows = [["name", material.get("name")], ["E, GPa", None if E is None else f"{E / 1e9:.4g}"],
             ["ν", material.get("nu")], ["ρ, kg/m³", rho]]
    for key, name in (("yield_strength_pa", "yield strength, MPa"),
                      ("ultimate_strength_pa", "ultimate strength, MPa")):
        if material.get(key):
            mrows.append([name, f"{material[key] / 1e6:.4g}"])
    if material.get("description"):
        mrows.append(["description", material["description"]])
    report.table(["quantity", "value"], mrows)
    heading("Supports")
    sup = modal.get("supports") or []
    if sup:
        report.table(["support", "fixed", "nodes"], [[s["label"], s["fix"], s["n_nodes"]]
                                                     for s in sup])
    else:
        report.paragraph(f"Free-free: {modal.get('rigid_body_modes')} rigid-body modes found "
                         f"and left out.")
    heading("Natural frequencies and mode shapes")
    held = carries_effective_mass(modal)
    header = MODE_HEADER if held else [h for h in MODE_HEADER if h not in EFFECTIVE_MASS_HEADER]
    report.table(header, mode_rows(modal, effective_mass=held))
    masses = ("Effective masses: translations in kg, rotations about the centre of mass in kg m²."
              if held else
              f"No effective-mass columns: the part is free-free, and its "
              f"{modal.get('rigid_body_modes')} rigid-body modes carry the whole mass, so every "
              f"elastic mode's effective mass is zero (to round-off).")
    report.paragraph(f"Largest eigen-residual ‖Kφ − λMφ‖/‖Kφ‖: "
                     f"{number(modal.get('residual_max', 0), 2)}; M-orthogonality defect "
                     f"{number(modal.get('m_orthogonality_max', 0), 2)}. "
                     + masses)
    if measured_hz:
        heading("Comparison with measured frequencies")
        report.paragraph(f"Verdict per mode: the difference from the measured frequency "
                         f"against the tolerance ±{percent(tolerance)} (report.tolerance).")
        report.table(MEASURED_HEADER, measured_rows(modal["frequencies_hz"], measured_hz,
                                                    tolerance))
    if mac:
        heading("MAC against the reference modes")
        report.paragraph(f"Reference: {mac['source']}. Pairs (mode ↔ reference, MAC): "
                         + ", ".join(f"{i + 1} ↔ {j + 1} ({v:.2f})" for i, j, v in mac["pairs"]))
        if mac.get("image"):
            report.image(mac["image"], "MAC matrix")
    if renders:
        heading("Mode-shape renders")
        for path, caption in render_images(renders):
            report.image(path, caption)
    for path, caption in extra_images:
        report.image(path, caption)
    if timings:
        heading("Timings")
        report.table(["step", "wall time"], [[k, quantity(v, "s", 3)] for k, v in timings.items()])
    if versions_table:
        heading("Versions")
        report.table(["package", "version"], [[k, v] for k, v in versions().items()])
    return report


def render_images(renders: dict) -> list[tuple[Path, str]]:
    """The pictures that show each rendered mode once: one animation per mode when there are
    GIFs, else the contact sheet (all modes, one camera), else the single still."""
    if renders.get("gifs"):
        return [(Path(p), Path(p).stem.replace("_", " ") + " (animated)")
                for p in renders["gifs"]]
    if renders.get("sheet"):
        return [(Path(renders["sheet"]), ("All modes (same camera; each mode also as "
                                          "mode_NN.png beside the report)"))]
    return [(Path(p), Path(p).stem.replace("_", " ")) for p in renders.get("modes", [])]


def write_report(report: Report, out_dir, stem: str = "report") -> dict:
    """Write ``<stem>.html`` and ``<stem>.md`` atomically into ``out_dir``."""
    from ..results import write_atomic

    out_dir = Path(out_dir)
    return {"html": write_atomic(out_dir / f"{stem}.html", report.to_html()),
            "markdown": write_atomic(out_dir / f"{stem}.md", report.to_markdown(out_dir))}
