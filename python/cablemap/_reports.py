"""The workflows that answer with a report: design, feasible, calibrate,
diagnose and predict.

Each function builds the request of the command of the same name from
keyword arguments named as its flags (``--tension-max-n`` is
``tension_max_n=``), runs the Rust library's workflow in process with the
GIL released, and returns a report object: the ``--json`` object's fields
as attributes, :meth:`Report.to_dict` equal to that object, the command's
text report as ``text`` (and ``str(report)``), a short ``repr`` and, in
notebooks, an HTML view with the pictures the workflow wrote.
"""

from __future__ import annotations

import base64
import html
import json
import os
from typing import Any, Dict, Iterable, List, Mapping, Optional, Sequence, Union

from . import Actuator, PathLike, _actuator, _dumps, _native, _solver
from ._record import Record
from .errors import BadInputError

__all__ = [
    "Report",
    "DesignReport",
    "FeasibleReport",
    "CalibrateReport",
    "DiagnoseReport",
    "PredictReport",
    "design",
    "feasible",
    "calibrate",
    "diagnose",
    "predict",
]


def _path(value: Optional[PathLike], what: str) -> Optional[str]:
    if value is None:
        return None
    if isinstance(value, (str, os.PathLike)):
        return os.fspath(value)
    raise BadInputError(f"{what}: expected a file or directory path, got {type(value).__name__}")


def _pairs(value: Union[str, Mapping[str, float], None], what: str) -> Optional[str]:
    """A target or weights as the flag's text ``K=V,…``, from the text or a dict."""
    if value is None or isinstance(value, str):
        return value
    if isinstance(value, Mapping):
        return ",".join(f"{k}={float(v)!r}" for k, v in value.items())
    raise BadInputError(f"{what}: expected \"K=V,…\" or a dict such as {{'x': 50, 'a0': -0.025}}, got {type(value).__name__}")


def _fix(fix: Union[Mapping[str, float], Iterable[str], None]) -> List[str]:
    """``fix`` as the ``--fix NAME=VALUE`` items."""
    if fix is None:
        return []
    if isinstance(fix, str):
        return [fix]
    if isinstance(fix, Mapping):
        return [f"{k}={float(v)!r}" for k, v in fix.items()]
    return [str(item) for item in fix]


def _effects(effects: Union[str, Iterable[str], None]) -> List[str]:
    if effects is None:
        return []
    if isinstance(effects, str):
        return [effects]
    return [str(e) for e in effects]


def _picture_html(path: str) -> str:
    """A picture for a notebook: a PNG embedded as base64, an SVG inline."""
    try:
        with open(path, "rb") as f:
            data = f.read()
    except OSError:
        return ""
    name = html.escape(os.path.basename(path))
    if path.endswith(".svg"):
        text = data.decode("utf-8", errors="replace")
        start = text.find("<svg")
        svg = text[start:] if start >= 0 else text
        return f"<figure style='margin:0.5em 0'><div style='max-width:100%;overflow:auto'>{svg}</div><figcaption>{name}</figcaption></figure>"
    encoded = base64.b64encode(data).decode("ascii")
    return (
        f"<figure style='margin:0.5em 0'><img style='max-width:100%' alt='{name}' "
        f"src='data:image/png;base64,{encoded}'/><figcaption>{name}</figcaption></figure>"
    )


def _num(v: Any, digits: int = 4) -> str:
    return "-" if v is None else f"{v:.{digits}g}" if isinstance(v, float) else str(v)


def _list(values: Optional[Sequence[Any]], digits: int = 4) -> str:
    return "[" + ", ".join(_num(v, digits) for v in (values or [])) + "]"


class Report(Record):
    """A workflow's report.

    - attributes: the fields of the command's ``--json`` object
      (``report.tension_n``, ``report.verdict``, …);
    - :meth:`to_dict`: that object, exactly;
    - ``text`` (also ``str(report)``): the report the command prints without ``--json``;
    - ``pictures``: paths of the pictures the workflow wrote (PNG, SVG), shown by
      ``_repr_html_`` in notebooks.
    """

    def __init__(self, record: Dict[str, Any], text: str, pictures: Sequence[str]) -> None:
        super().__init__(record)
        #: The command's text report.
        self.text = text
        #: Paths of the pictures the workflow wrote.
        self.pictures = list(pictures)

    def __str__(self) -> str:
        return self.text

    def _lines(self) -> List[str]:
        """The summary: the answer first, then the key numbers."""
        return []

    def __repr__(self) -> str:
        return "\n  ".join([f"{type(self).__name__}:"] + self._lines())

    def _repr_html_(self) -> str:
        lines = self._lines()
        head = f"<b>{html.escape(type(self).__name__)}</b>: {html.escape(lines[0]) if lines else ''}"
        items = "".join(f"<li>{html.escape(line)}</li>" for line in lines[1:])
        pictures = "".join(_picture_html(p) for p in self.pictures)
        return (
            f"<div class='cablemap-report'><p>{head}</p><ul>{items}</ul>{pictures}"
            f"<details><summary>the command's report</summary><pre>{html.escape(self.text)}</pre></details></div>"
        )


class DesignReport(Report):
    """A design: ``cablemap design --json``'s object (design.json's fields:
    ``routing_mm``, ``tension_n``, ``tip_x_mm``, ``tip_y_mm``, ``a``,
    ``error_pct``, ``met``, ``unmet``, ``cost``, …; with ``targets=``, the
    several-cable object: ``cables``, ``targets``, ``met``, ``unmet``,
    ``cost``, ``method``, …). ``pictures``: shape.png and mould.svg (or
    target_N.png) when ``out`` was given."""

    def _lines(self) -> List[str]:
        r = self._record
        unmet = [str(u) for u in r["unmet"]]
        listed = "; ".join(unmet[:2]) + (f"; and {len(unmet) - 2} more" if len(unmet) > 2 else "")
        verdict = "met: every component within the tolerance" if r["met"] else f"NOT met ({listed}): the closest design"
        lines = [verdict]
        if "routing_mm" in r:
            lines.append(f"routing_mm = {_list(r['routing_mm'], 5)}, tension_n = {r['tension_n']:.4f}")
            lines.append(f"tip = ({r['tip_x_mm']:.3f}, {r['tip_y_mm']:.3f}) mm, a = {_list(r['a'], 5)} mm^-1 ({r['length_basis']} basis)")
            errors = ", ".join(f"{k} {_num(v, 3)}%" for k, v in r["error_pct"].items())
            lines.append(f"error: {errors}")
        else:
            for i, c in enumerate(r["cables"], 1):
                lines.append(f"cable {i}: y_mm = {_list(c['y_mm'], 4)}, z_mm = {_list(c['z_mm'], 4)}")
            for t in r["targets"]:
                lines.append(f"{t['name']}: tensions_n = {_list(t['tensions_n'], 4)}, tip off by {_num(t.get('tip_error_mm'), 3)} mm")
        lines.append(f"cost = {r['cost']:.3e}, {len(r['starts'])} starts, {r['seconds']:.2f} s")
        return lines


class FeasibleReport(Report):
    """A map's verdict: ``cablemap feasible --json``'s object (``verdict``,
    ``reasons``, ``tip_cell``, ``coefficients``, ``mode``, ``nearest``, …;
    with ``study=``, ``feasible_variants`` and ``variants``; with
    ``targets=``, the cable sweep's answer per target)."""

    def _lines(self) -> List[str]:
        r = self._record
        if "verdict" in r:
            lines = [f"verdict: {r['verdict']}"] + [f"- {reason}" for reason in r["reasons"]]
            if r.get("nearest"):
                n = r["nearest"][0]
                lines.append(
                    f"nearest design: routing_mm = {_list(n.get('routing_mm'), 4)}, tension_n = {_num(n.get('tension_n'))}, "
                    f"tip = ({_num(n.get('tip_x_mm'))}, {_num(n.get('tip_y_mm'))}) mm, distance {_num(n.get('distance'))}"
                )
            return lines
        if "variants" in r:
            return [f"feasible variants: {', '.join(r['feasible_variants']) or 'none'}"] + [
                f"v{v['variant']} {v['label']}: {v['verdict']}" for v in r["variants"]
            ]
        lines = [f"{len(r.get('targets', []))} target(s) against the map {r.get('map')}"]
        for t in r.get("targets", []):
            brief = {k: v for k, v in t.items() if isinstance(v, (str, int, float, bool))}
            lines.append(json.dumps(brief)[:160])
        return lines


def _parameters(r: Dict[str, Any]) -> List[str]:
    out = []
    for p in r.get("parameters", []):
        name = p.get("name", "?")
        value, se = p.get("value"), p.get("se", p.get("standard_error"))
        out.append(f"{name} = {_num(value, 6)}" + (f" ± {_num(se, 2)}" if se is not None else ""))
    return out


class CalibrateReport(Report):
    """A calibration: ``cablemap calibrate --json``'s object (the fitted
    ``parameters`` with their standard errors, ``correlation``, the RMS
    errors, ``chi2``, …; with ``actuator=``, the 3-D fit's, as fit.json)."""

    def _lines(self) -> List[str]:
        r = self._record
        head = "converged" if r.get("converged") else f"stopped: {r.get('termination', 'not converged')}"
        lines = [f"{head} after {r.get('iterations')} iterations"]
        params = _parameters(r)
        if params:
            lines.append(", ".join(params))
        rms = {k: v for k, v in r.items() if k.startswith("rms") and isinstance(v, float)}
        if rms:
            lines.append(", ".join(f"{k} = {v:.4g}" for k, v in sorted(rms.items())))
        if "reduced_chi2" in r:
            lines.append(f"reduced chi2 = {_num(r['reduced_chi2'])}, p = {_num(r.get('p_value'))}")
        return lines


class DiagnoseReport(Report):
    """A diagnosis: ``cablemap diagnose --json``'s object (``verdict``,
    ``reason``, ``effects`` named, ``parameter``, ``candidates``, the
    ``baseline``, ``extended`` and ``best`` fits, …). ``pictures``: the
    report's plots (residuals.png, loops.png, shapes.png) when it wrote
    them."""

    def _lines(self) -> List[str]:
        r = self._record
        lines = [f"verdict: {r.get('verdict')}", str(r.get("reason", ""))]
        if r.get("parameter_name"):
            lines.append(f"{r['parameter_name']} = {_num(r.get('parameter'), 6)} ± {_num(r.get('parameter_se'), 2)}")
        if r.get("report"):
            lines.append(f"report: {r['report']}")
        return lines


class PredictReport(Report):
    """A prediction: ``cablemap predict --json``'s object (``actuator``,
    ``captures`` with each capture's marker errors, ``rms_by_marker_mm``,
    ``rms_mm``)."""

    def _lines(self) -> List[str]:
        r = self._record
        markers = ", ".join(f"{k} {v:.2f}" for k, v in r.get("rms_by_marker_mm", {}).items())
        return [f"marker RMS {r['rms_mm']:.3f} mm over {len(r.get('captures', []))} captures", f"by marker (mm): {markers}", f"actuator: {r['actuator']}"]


def _run(kind: type, function: Any, request: Dict[str, Any]) -> Any:
    record, text, pictures = function(_dumps(request))
    return kind(json.loads(record), text, pictures)


def design(
    target: Union[str, Mapping[str, float], None] = None,
    *,
    targets: Optional[PathLike] = None,
    actuator: Union[Actuator, PathLike, None] = None,
    weights: Union[str, Mapping[str, float], None] = None,
    map: Optional[PathLike] = None,
    tension_min_n: Optional[float] = None,
    tension_max_n: Optional[float] = None,
    max_offset_mm: Optional[float] = None,
    length_basis: str = "rest",
    starts: Optional[int] = None,
    max_evaluations: Optional[int] = None,
    tolerance_pct: Optional[float] = None,
    out: Optional[PathLike] = None,
    moulds: bool = False,
    wall_mm: Optional[float] = None,
    tube_diameter_mm: Optional[float] = None,
    clearance_mm: Optional[float] = None,
    clamp_mm: Optional[float] = None,
    min_skin_mm: Optional[float] = None,
    method: Optional[str] = None,
    nodes_per_span: Optional[int] = None,
    steps_per_span: Optional[int] = None,
    **actuator_fields: Any,
) -> DesignReport:
    """Designs the routing and tension for a target shape, as ``cablemap design --json``.

    Two requests, as the command has them:

    - ``target`` (``"x=50,y=5,a0=-0.025"`` or ``{"x": 50, "a0": -0.025}``):
      the planar design (thesis eq. 3.17, ``design --target``) of one cable on
      the rod ``actuator`` (an :class:`Actuator` without cables or an actuator
      file's path; the thesis's when left out) with ``**actuator_fields`` set.
      ``weights``, ``tension_min_n``, ``tension_max_n``, ``max_offset_mm``,
      ``map``, ``starts`` (default 8), ``tolerance_pct`` (default 5) as the flags.
    - ``targets`` (a targets TOML file, ``design --targets``): the
      several-cable design of every cable of ``actuator`` (the design
      actuator file's path: free channels, tension bounds; one cable free in
      y on the thesis's rod when left out), ``**actuator_fields`` set on its rod.

    ``out`` writes design.json, channel.csv, mould.svg and shape.png (or
    target_N.png) there, shown in notebooks; ``moulds=True`` with ``out``
    designs within what the moulds can cast and writes them (``wall_mm``,
    ``tube_diameter_mm``, ``clearance_mm``, ``clamp_mm``, ``min_skin_mm``).
    ``length_basis``, ``max_evaluations``, ``method``, ``nodes_per_span``,
    ``steps_per_span``: as the flags. Raises :class:`BadInputError` for
    input the library refuses, :class:`FileFormatError` for a map or file
    it cannot read.
    """
    if (target is None) == (targets is None):
        raise BadInputError("give target= (one planar cable) or targets=FILE.toml (several cables), one of them")
    request: Dict[str, Any] = {
        "target": _pairs(target, "target"),
        "targets": _path(targets, "targets"),
        "weights": _pairs(weights, "weights"),
        "map": _path(map, "map"),
        "tension_min_n": tension_min_n,
        "tension_max_n": tension_max_n,
        "max_offset_mm": max_offset_mm,
        "length_basis": length_basis,
        "starts": starts,
        "max_evaluations": max_evaluations,
        "tolerance_pct": tolerance_pct,
        "out": _path(out, "out"),
        "moulds": bool(moulds),
        "mould": {
            k: v
            for k, v in dict(
                wall_mm=wall_mm, tube_diameter_mm=tube_diameter_mm, clearance_mm=clearance_mm, clamp_mm=clamp_mm, min_skin_mm=min_skin_mm
            ).items()
            if v is not None
        },
        "solver": _solver(method, nodes_per_span, steps_per_span),
    }
    if targets is not None and isinstance(actuator, (str, os.PathLike)):
        # The design actuator file (free channels, bounds): read by the library.
        request["actuator"] = Actuator.thesis().to_dict()
        request["design_actuator"] = os.fspath(actuator)
        request["rod_fields"] = {k: v for k, v in actuator_fields.items() if v is not None}
    else:
        request["actuator"] = _actuator(actuator, actuator_fields).to_dict()
    return _run(DesignReport, _native.design, request)


def feasible(
    target: Union[str, Mapping[str, float], None] = None,
    *,
    map: Optional[PathLike] = None,
    study: Optional[PathLike] = None,
    targets: Optional[PathLike] = None,
    weights: Union[str, Mapping[str, float], None] = None,
    nearest: int = 5,
    length_basis: str = "rest",
) -> FeasibleReport:
    """A feasibility map's verdict on a target, as ``cablemap feasible --json``.

    ``map`` (a ``cablemap reduce`` output) or ``study`` (a ``cablemap
    study`` output: every variant's verdict) judges ``target`` (``"x=…,a0=…"``
    or a dict); ``targets`` (a targets TOML file) with the ``map`` of a cable
    sweep says whether the sweep reached each target. ``weights``,
    ``nearest`` (designs listed), ``length_basis``: as the flags.
    """
    request = {
        "map": _path(map, "map"),
        "study": _path(study, "study"),
        "target": _pairs(target, "target"),
        "targets": _path(targets, "targets"),
        "weights": _pairs(weights, "weights"),
        "nearest": int(nearest),
        "length_basis": length_basis,
    }
    return _run(FeasibleReport, _native.feasible, request)


# The settings every fit shares, by their names in calibrate() and diagnose().
_FIT_SETTINGS = ("holdout", "holdout_cable", "noise_mm", "noise_deg", "loss", "huber_k", "max_iterations", "angle_weight")


def _fit_request(args: Dict[str, Any]) -> Dict[str, Any]:
    """The request of a fit from the arguments of :func:`calibrate` or :func:`diagnose`."""
    if isinstance(args["actuator"], Actuator):
        raise BadInputError("actuator: give the actuator file's path (write an Actuator with .write(path))")
    fields = {k: v for k, v in args["rod_fields"].items() if v is not None}
    if args["actuator_file"] is not None:
        fields["actuator_file"] = _path(args["actuator_file"], "actuator_file")
    request = {key: _path(args[key], key) for key in ("data", "actuator", "markers", "centrelines", "out")}
    request.update({key: args[key] for key in _FIT_SETTINGS})
    request.update(rod_fields=fields, fix=_fix(args["fix"]), solver=_solver(args["method"], args["nodes_per_span"], args["steps_per_span"]))
    return request


def calibrate(
    data: PathLike,
    *,
    actuator: Optional[PathLike] = None,
    markers: Optional[PathLike] = None,
    centrelines: Optional[PathLike] = None,
    out: Optional[PathLike] = None,
    effects: Union[str, Iterable[str], None] = None,
    fix: Union[Mapping[str, float], Iterable[str], None] = None,
    holdout: Optional[str] = None,
    holdout_cable: Optional[int] = None,
    noise_mm: float = 0.4,
    noise_deg: float = 1.0,
    loss: Optional[str] = None,
    huber_k: float = 3.0,
    max_iterations: int = 200,
    angle_weight: float = 1.0,
    actuator_file: Optional[PathLike] = None,
    method: Optional[str] = None,
    nodes_per_span: Optional[int] = None,
    steps_per_span: Optional[int] = None,
    **rod_fields: Any,
) -> CalibrateReport:
    """Fits the rod to measurements, as ``cablemap calibrate DATA --json``.

    - Planar (``data`` a measurement file, docs/measurements.md): fits EA,
      GA, EI and the ``effects`` (``"friction"``, ``"stiffening"``, …) from
      the data's rod, or ``actuator_file``'s (a rod file), with
      ``**rod_fields`` set (``ei_n_mm2=…``, ``gravity=False``,
      ``creep_time_s=…``); ``centrelines``, ``markers``, ``holdout`` (a
      routing left out), ``noise_deg``, ``angle_weight`` as the flags.
    - 3-D (``actuator`` an actuator file's path, ``data`` a captures file,
      ``markers`` the 3-D markers): fits the body by the 3-D solver;
      ``holdout_cable`` fits on the captures where that cable does not pull;
      ``out`` writes calibrated.toml and fit.json there.

    ``fix`` holds parameters (``{"GA": 1.70866}`` or ``["GA=1.70866"]``);
    ``loss`` ``"huber"`` (planar default) or ``"squares"`` (3-D default),
    ``huber_k``, ``noise_mm``, ``max_iterations``, ``method``,
    ``nodes_per_span``, ``steps_per_span``: as the flags.
    """
    request = _fit_request(locals())
    request["effects"] = _effects(effects)
    return _run(CalibrateReport, _native.calibrate, request)


def diagnose(
    data: PathLike,
    *,
    actuator: Optional[PathLike] = None,
    markers: Optional[PathLike] = None,
    centrelines: Optional[PathLike] = None,
    out: Optional[PathLike] = None,
    report: bool = True,
    fix: Union[Mapping[str, float], Iterable[str], None] = None,
    holdout: Optional[str] = None,
    holdout_cable: Optional[int] = None,
    noise_mm: float = 0.4,
    noise_deg: float = 1.0,
    loss: Optional[str] = None,
    huber_k: float = 3.0,
    max_iterations: int = 200,
    angle_weight: float = 1.0,
    alpha: float = 1e-3,
    threshold: float = 10.0,
    margin: float = 10.0,
    max_effects: int = 2,
    actuator_file: Optional[PathLike] = None,
    method: Optional[str] = None,
    nodes_per_span: Optional[int] = None,
    steps_per_span: Optional[int] = None,
    **rod_fields: Any,
) -> DiagnoseReport:
    """Finds, names and adds the effect the model misses, as ``cablemap diagnose DATA --json``.

    The report (report.md and its pictures, shown in notebooks) goes to
    ``out``, by default beside the data (``m.csv`` → ``m-diagnosis/``);
    ``report=False`` writes none (``--no-report``). With ``actuator`` (an
    actuator file's path): captures and 3-D markers, by the 3-D solver (a
    picture per capture).
    ``alpha``, ``threshold``, ``margin``, ``max_effects`` and the fit's
    settings (see :func:`calibrate`) as the flags.
    """
    request = _fit_request(locals())
    request.update(alpha=float(alpha), threshold=float(threshold), margin=float(margin), max_effects=int(max_effects))
    request["report"] = bool(report)
    return _run(DiagnoseReport, _native.diagnose, request)


def predict(
    captures: PathLike,
    actuator: PathLike,
    *,
    markers: Optional[PathLike] = None,
    method: Optional[str] = None,
    nodes_per_span: Optional[int] = None,
    steps_per_span: Optional[int] = None,
) -> PredictReport:
    """Simulates every capture with the actuator file's actuator (no fitting)
    and reports the markers' 3-D errors, as ``cablemap predict CAPTURES
    --actuator A.toml --json``."""
    request = {
        "captures": _path(captures, "captures"),
        "actuator": _path(actuator, "actuator"),
        "markers": _path(markers, "markers"),
        "solver": _solver(method, nodes_per_span, steps_per_span),
    }
    return _run(PredictReport, _native.predict, request)
