"""Machine-readable results of validation runs: JUnit XML for CI pipelines, and a JSON document.

Every check is named `<model>.<route>.<quantity>` (routes: the engine routes and "reference";
published values: `<model>.published.<symbol>`) and carries its measured error and tolerance,
also when it passes, and what it rests on (trust: an independent engine, the 40-digit
re-solution, a published value). NaN is written as null.

May use: the standard library, the runs room and `kinetostat._text` (XML-safe text).
"""
from __future__ import annotations

import math
import xml.etree.ElementTree as ET
from typing import Any, Sequence

from .._text import xml_clean_tree
from .runs import PUBLISHED_ROUTE, Check, ModelRun, quantities, trust


def _number(x: float) -> float | None:
    x = float(x)
    return x if math.isfinite(x) else None


def _text(x: float) -> str:
    return "null" if not math.isfinite(x) else repr(float(x))


def _case(suite: ET.Element, run: ModelRun, route: str, name: str, secs: float) -> ET.Element:
    return ET.SubElement(suite, "testcase", classname=f"{run.stem}.{route}", name=name, time=f"{secs:.6f}")


def _trust(case: ET.Element, what: str) -> None:
    """A check that did not run (skipped route) still says what it would rest on."""
    ET.SubElement(ET.SubElement(case, "properties"), "property", name="trust", value=what)


def _measured(case: ET.Element, c: Check) -> None:
    """The check's numbers as <properties> of its testcase, and its one line as <system-out>."""
    props = ET.SubElement(case, "properties")
    for key, value in (("error", _text(c.error)), ("measure", c.measure), ("tolerance", _text(c.tolerance)),
                       ("max_abs", _text(c.max_abs)), ("unit", c.unit), ("phi_deg", _text(c.phi_deg)),
                       ("trust", c.trust)):
        ET.SubElement(props, "property", name=key, value=value)
    ET.SubElement(case, "system-out").text = c.detail


def junit_xml(runs: Sequence[ModelRun], name: str = "kinetostat validate") -> ET.ElementTree:
    """One testsuite per model; one testcase per route x quantity and per published value.
    Failures as <failure>, skipped routes as <skipped>, a route that raised as <error> on each of
    its quantities; every check that ran carries its error and tolerance (<properties>)."""
    root = ET.Element("testsuites", name=name)
    totals = dict(tests=0, failures=0, errors=0, skipped=0)
    total_time = 0.0
    for run in runs:
        suite = ET.SubElement(root, "testsuite", name=run.stem)
        props = ET.SubElement(suite, "properties")
        ET.SubElement(props, "property", name="model", value=str(run.path or run.mech.name))
        ET.SubElement(props, "property", name="structure", value=run.mech.structure.formula)
        ET.SubElement(props, "property", name="positions", value=str(len(run.res.phi_deg)))
        counts = dict(tests=0, failures=0, errors=0, skipped=0)
        checks = {(c.route, c.quantity): c for c in run.checks}
        cases: list[tuple[str, list[str]]] = [(route, quantities(run.mech, route)) for route in run.engines]
        symbols = [c.entry.symbol for c in run.published]
        if PUBLISHED_ROUTE in run.errors:
            cases.append((PUBLISHED_ROUTE, ["(all)"]))
        elif symbols:
            cases.append((PUBLISHED_ROUTE, symbols))
        for route, names in cases:
            secs = run.seconds.get(route, 0.0) / max(len(names), 1)
            for q in names:
                case = _case(suite, run, route, q, secs)
                counts["tests"] += 1
                c = checks.get((route, q))
                if route in run.errors:
                    ET.SubElement(case, "error", message=run.errors[route], type="RouteError")
                    counts["errors"] += 1
                elif route in run.skipped:
                    ET.SubElement(case, "skipped", message=run.skipped[route])
                    _trust(case, trust(route))
                    counts["skipped"] += 1
                elif c is None:
                    ET.SubElement(case, "error", message=f"route {route} returned no row for {q}", type="MissingRow")
                    counts["errors"] += 1
                else:
                    if not c.passed:
                        ET.SubElement(case, "failure", type="ToleranceExceeded", message=c.detail).text = c.detail
                        counts["failures"] += 1
                    _measured(case, c)
        t = sum(run.seconds.values())
        total_time += t
        for k, v in counts.items():
            suite.set(k, str(v))
            totals[k] += v
        suite.set("time", f"{t:.6f}")
    for k, v in totals.items():
        root.set(k, str(v))
    root.set("time", f"{total_time:.6f}")
    xml_clean_tree(root)
    tree = ET.ElementTree(root)
    ET.indent(tree)
    return tree


def validation_json(runs: Sequence[ModelRun], exit_code: int) -> dict[str, Any]:
    """The runs as a JSON-ready dict: per model its checks (name, route, quantity, error, measure,
    tolerance, max_abs, unit, phi_deg, passed, trust: what it rests on), skipped and failed routes,
    its status ("passed", "failed", or "not checked": nothing compared it); totals; the exit code."""
    models = []
    for run in runs:
        checks = [dict(name=c.name, route=c.route, quantity=c.quantity, error=_number(c.error), measure=c.measure,
                       tolerance=_number(c.tolerance), max_abs=_number(c.max_abs), unit=c.unit,
                       phi_deg=_number(c.phi_deg), passed=bool(c.passed), trust=c.trust) for c in run.checks]
        models.append(dict(model=run.stem, path=None if run.path is None else str(run.path), name=run.mech.name,
                           structure=run.mech.structure.formula, positions=len(run.res.phi_deg),
                           passed=bool(run.passed and run.checked),
                           status="failed" if not run.passed else "passed" if run.checked else "not checked",
                           checks=checks, skipped=dict(run.skipped),
                           errors=dict(run.errors),
                           seconds={r: _number(s) for r, s in run.seconds.items()}))
    every = [c for m in models for c in m["checks"]]
    totals = dict(models=len(models), checks=len(every), passed=sum(c["passed"] for c in every),
                  failed=sum(not c["passed"] for c in every),
                  route_errors=sum(len(m["errors"]) for m in models),
                  routes_skipped=sum(len(m["skipped"]) for m in models),
                  not_checked=sum(m["status"] == "not checked" for m in models))
    return dict(passed=exit_code == 0, exit_code=exit_code, totals=totals, models=models)
