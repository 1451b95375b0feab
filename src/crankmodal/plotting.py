"""matplotlib for files, never a window, and never a change to the user's pyplot.

crankmodal's figures are ``matplotlib.figure.Figure`` objects on their own Agg canvas: they belong
to no pyplot figure manager and switch no backend, so a user's own ``plt.show()`` in Jupyter or a
script works as before after a crankmodal run (an earlier version called ``matplotlib.use("Agg")``
on the first figure, and the user's windows stopped showing).
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
