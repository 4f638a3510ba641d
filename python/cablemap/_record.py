"""The one record-backed object every result and report of the package is:
the library's JSON object as attributes, ``to_dict()`` returning exactly the
command's ``--json`` object."""

from __future__ import annotations

import json
from typing import Any, Dict, List


class Record:
    """A result or report: its fields (the command's ``--json`` object) as
    attributes, ``to_dict()`` for the object itself."""

    _record: Dict[str, Any]

    def __init__(self, record: Dict[str, Any]) -> None:
        self._record = record

    def __getattr__(self, name: str) -> Any:
        record = self.__dict__.get("_record", {})
        if name in record:
            return record[name]
        raise AttributeError(f"{type(self).__name__} has no field {name!r}; its fields are {', '.join(sorted(record))}")

    def __dir__(self) -> List[str]:
        return sorted(set(super().__dir__()) | set(self._record))

    def to_dict(self) -> Dict[str, Any]:
        """The record: exactly the command's ``--json`` object."""
        return json.loads(json.dumps(self._record))
