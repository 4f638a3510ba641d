"""The extension module (Rust): JSON requests in, records and f64 bytes out."""

from typing import Any, Dict, List, Optional, Tuple

CENTRELINE_COLUMNS: List[str]
BATCH_FIELDS: List[str]

def actuator_from_fields(base_json: Optional[str], fields_json: str) -> str: ...
def actuator_read(path: str, rod_only: bool) -> str: ...
def actuator_to_toml(actuator_json: str) -> str: ...
def simulate(request_json: str) -> Tuple[str, bytes, List[str]]: ...
def solve_batch(
    actuator_json: str,
    routings_mm: List[float],
    tensions_n: List[float],
    order: int,
    length_basis: str,
    solver_json: str,
    threads: Optional[int] = ...,
) -> Dict[str, Any]: ...
