"""matplotlib for files, never a window: the one place crankmodal sets up pyplot."""


def pyplot():
    """``matplotlib.pyplot`` on the Agg backend (PNG files, no display needed).

    Imported on first call, so importing a plotting module costs nothing until a figure is made.
    """
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt
