"""The exceptions of cablemap: each carries the library's message.

- ``CablemapError``: the base of all of them.
- ``BadInputError`` (also a ``ValueError``): input the library refuses (a
  routing outside the rod, an unknown actuator field, a negative tension, ...).
- ``SolveError`` (also a ``RuntimeError``): a solve that produced no result;
  ``status`` is the status a sweep stores for it (``unresolved``,
  ``non_finite``, ...).
- ``FileFormatError`` (also an ``OSError``): a file that cannot be read or
  parsed (an actuator TOML file, a run or map directory).
"""


class CablemapError(Exception):
    """Base class of cablemap's errors; ``str(e)`` is the library's message."""


class BadInputError(CablemapError, ValueError):
    """Input the library refuses; the message names the problem and what to do."""


class SolveError(CablemapError, RuntimeError):
    """A solve that produced no result."""

    def __init__(self, message: str, status: str = "failed"):
        super().__init__(message)
        #: The status a sweep stores for this failure (``unresolved``, ``non_finite``, ...).
        self.status = status


class FileFormatError(CablemapError, OSError):
    """A file or directory that cannot be read or parsed."""


__all__ = ["CablemapError", "BadInputError", "SolveError", "FileFormatError"]
