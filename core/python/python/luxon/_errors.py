"""Luxon's exceptions. Every message is the text the ``luxon`` command prints after
``luxon: error:``; errors in a scene file or in RON text also carry where they are."""


class LuxonError(Exception):
    """Base class of every error Luxon raises (a bug in Luxon is one too: its message says
    "internal error")."""


class SceneError(LuxonError):
    """A scene file or RON text Luxon cannot use. ``str(e)`` is ``file:line:col: message``,
    as the command line prints it.

    Attributes: ``file`` (str: the scene file, or ``<camera>``, ``<light>``, ``<object 3>``...
    for text given to a method), ``line`` and ``column`` (int, 1-based; None when the error
    is about the file as a whole, e.g. a file that does not exist).
    """

    file = None
    line = None
    column = None


class PluginError(LuxonError):
    """A plugin failed (it panicked, or returned an error outside any scene position)."""


class CancelledError(LuxonError):
    """The render was cancelled."""


class UsageError(LuxonError, ValueError):
    """A call given what it cannot take (a removed light's id, a size out of range...)."""


class FileError(LuxonError, OSError):
    """A file could not be written or read; ``file`` names it."""

    file = None
    line = None
    column = None


class OutOfMemoryError(LuxonError, MemoryError):
    """An allocation sized by the scene's data that the system refused."""
