"""User-facing errors.

Anything a user can cause (a bad scene value, a missing file, impossible geometry) raises a
subclass of :class:`CrankmodalError`. The CLI turns it into one line on stderr and exit status 2
(3 for :class:`NumericalError`), never a traceback.
"""


class CrankmodalError(Exception):
    """Base class of the errors a user can fix; the message names the offending value.

    Attributes
    ----------
    exit_code : int
        The CLI's exit status for it: 2 (bad input; 3 for :class:`NumericalError`).
    """

    exit_code = 2


class SceneError(CrankmodalError):
    """A scene key is unknown, of the wrong type, or out of its admissible range.

    Attributes
    ----------
    exit_code : int
        2: the CLI exits with status 2 and one line naming the key; no results.json is written.
    """


class InputFileError(CrankmodalError):
    """A file named in a scene is missing or unreadable.

    Attributes
    ----------
    exit_code : int
        2: the CLI exits with status 2 and one line naming the file (and member, where it has one).
    """


class FileMemberError(InputFileError):
    """A saved file (flexbody, dynamics or fatigue result, ...) that cannot be trusted:
    unreadable, of another format, or a member of the wrong kind, shape or value. The message
    names the file and the member.

    Attributes
    ----------
    path : str
        The file.
    member : str
        The offending member (``""``: the file as a whole).
    text : str
        What is wrong with it.
    exit_code : int
        2, as :class:`InputFileError`.
    """

    def __init__(self, path, member: str = "", text: str | None = None):
        if text is None:  # one argument: a message re-raised under a scene key, as it is
            self.path, self.member, self.text = "", member, str(path)
            super().__init__(str(path))
            return
        self.path, self.member, self.text = str(path), member, text
        where = f"{path}: member {member!r}" if member else str(path)
        super().__init__(f"{where}: {text}")

    def __reduce__(self):  # picklable (a study's worker raises it in another process)
        return type(self), (self.path, self.member, self.text)


class OutputError(CrankmodalError):
    """An output file or folder cannot be written (the folder is a file, read-only, the disk is
    full); the message names the path and the system's reason.

    Attributes
    ----------
    exit_code : int
        2: the CLI exits with status 2 and one line; nothing is half-written.
    """


class GeometryError(CrankmodalError):
    """A parameter set describes an impossible part, or the geometry kernel failed on it.

    Attributes
    ----------
    exit_code : int
        2: the CLI exits with status 2 and one line naming the parameter.
    """


class ResourceError(CrankmodalError):
    """The problem needs more of this machine (memory) than it has; the message says how much
    and what to change. Raised before the allocation, instead of the kernel killing the run."""


class NumericalError(CrankmodalError):
    """A computation did not meet its own accuracy checks; the message says what to change.

    Attributes
    ----------
    exit_code : int
        3: the CLI exits with status 3 and one line of advice.
    """

    exit_code = 3


class ModelWarning(UserWarning):
    """A model that will compute, but whose answer deserves suspicion (locking, units, impacts
    shorter than the output step). The CLI prints it as one ``crankmodal: warning:`` line and the
    stage keeps it in its ``warnings`` in results.json."""


def warn(text: str, into: list | None = None) -> None:
    """Issue a :class:`ModelWarning` and, with ``into``, keep its text there (a stage's
    ``warnings`` in results.json)."""
    import warnings

    warnings.warn(text, ModelWarning, stacklevel=3)
    if into is not None:
        into.append(text)


class ParameterError(CrankmodalError, ValueError):
    """An argument of a core (Python API) function is out of its admissible range.

    The message names the argument (``n_modes: must be >= 1, got 0``). Core functions raise it
    and know nothing of scenes; a stage that read the value from a scene re-raises it as a
    :class:`SceneError` naming the scene key (``modal.n_modes: ...``) with :func:`scene_keys`.

    Attributes
    ----------
    argument : str
        The argument's name (a dotted path for nested values, e.g. ``supports[1].fix``).
    text : str
        What is wrong, without the name.
    """

    def __init__(self, argument: str, text: str):
        self.argument = argument
        self.text = text
        super().__init__(f"{argument}: {text}")

    def __reduce__(self):
        # picklable as raised (a Dask worker sends it back to the client)
        return type(self), (self.argument, self.text)


class scene_keys:
    """Re-raise :class:`ParameterError` inside the block as :class:`SceneError` under ``prefix``.

    ``keys`` maps an argument name to its scene key when they differ (``{"sigma": "shift"}``);
    other names are used as they are. Example::

        with scene_keys("modal", {"sigma": "shift"}):
            modes = solve_modes(model, n_modes=table["n_modes"], sigma=table["shift"])
    """

    def __init__(self, prefix: str, keys: dict | None = None):
        self.prefix = prefix
        self.keys = keys or {}

    def __enter__(self):
        return self

    def __exit__(self, kind, exc, tb):
        if isinstance(exc, ParameterError):
            head, dot, rest = exc.argument.partition(".")
            base, bracket, index = head.partition("[")
            name = self.keys.get(exc.argument) or (self.keys.get(base, base) + bracket + index
                                                   + dot + rest)
            raise SceneError(f"{self.prefix}.{name}: {exc.text}") from None
        return False
