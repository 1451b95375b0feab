"""matplotlib for files, never a window, and never a change to the user's pyplot.

crankmodal's figures are ``matplotlib.figure.Figure`` objects on their own Agg canvas: they belong
to no pyplot figure manager and switch no backend, so a user's own ``plt.show()`` in Jupyter or a
script works as before after a crankmodal run (an earlier version called ``matplotlib.use("Agg")``
on the first figure, and the user's windows stopped showing).

:func:`visible_curves` decides which curves a figure draws and lists in its legend: a curve that
would lie on the axis (zero) or under another one is named in a note instead (issue 25 #15).
"""


class _FileFigures:
    """The part of ``matplotlib.pyplot``'s interface the plotting modules use, for file figures."""

    @staticmethod
    def figure(**figure_kw):
        """A ``Figure`` with an Agg canvas (PNG output, no display, no pyplot state)."""
        from matplotlib.backends.backend_agg import FigureCanvasAgg
        from matplotlib.figure import Figure

        fig = Figure(**figure_kw)
        FigureCanvasAgg(fig)
        return fig

    def subplots(self, nrows=1, ncols=1, *, sharex=False, sharey=False, squeeze=True,
                 subplot_kw=None, gridspec_kw=None, **figure_kw):
        """``(fig, axes)`` as ``pyplot.subplots`` returns them."""
        fig = self.figure(**figure_kw)
        axes = fig.subplots(nrows, ncols, sharex=sharex, sharey=sharey, squeeze=squeeze,
                            subplot_kw=subplot_kw, gridspec_kw=gridspec_kw)
        return fig, axes

    @staticmethod
    def close(fig=None):
        """Nothing to release: no figure manager holds the figure; it goes with its last reference."""

    @staticmethod
    def get_cmap(name):
        """A registered colormap by name."""
        import matplotlib

        return matplotlib.colormaps[name]


_FIGURES = _FileFigures()


def pyplot():
    """A stand-in for ``matplotlib.pyplot`` whose ``subplots``/``figure`` make file figures.

    Imported on first use, so importing a plotting module costs nothing until a figure is made.
    """
    return _FIGURES


#: a curve whose largest magnitude is below this fraction of the figure's largest is not drawn:
#: it would lie on the origin (or the axis) where nobody can see it; a note names it instead
ZERO_FRACTION = 1e-3
#: a curve within this fraction of the figure's largest magnitude of an already drawn one is
#: not drawn: it would hide under that one; the note says it coincides
COINCIDE_FRACTION = 5e-3


def visible_curves(curves):
    """Split labelled curves into those a reader can see and notes on those left out.

    Parameters
    ----------
    curves : list of (str, ndarray)
        Label and data (any shape; compared element by element, in the same unit).

    Returns
    -------
    drawn : list of (str, ndarray)
        Curves to draw (and only these in the legend).
    hidden : list of str
        ``'<label> (zero)'`` or ``'<label> (= <other>)'`` for each curve left out.
    """
    import numpy as np

    scale = max((float(np.max(np.abs(c))) for _, c in curves), default=0.0)
    drawn, hidden = [], []
    for label, c in curves:
        c = np.asarray(c, float)
        if float(np.max(np.abs(c))) <= ZERO_FRACTION * scale:
            hidden.append(f"{label} (zero)")
            continue
        same = next((k for k, d in drawn if d.shape == c.shape
                     and float(np.max(np.abs(d - c))) <= COINCIDE_FRACTION * scale), None)
        if same is not None:
            hidden.append(f"{label} (= {same})")
            continue
        drawn.append((label, c))
    return drawn, hidden


def hidden_note(ax, hidden) -> None:
    """Name the curves not drawn, in the lower left corner of the axes."""
    if hidden:
        ax.text(0.01, 0.01, "not drawn: " + ", ".join(hidden), transform=ax.transAxes,
                fontsize=7, color="0.3", va="bottom")
