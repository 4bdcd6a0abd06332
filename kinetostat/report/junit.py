"""JUnit XML of validation runs, for CI pipelines.

May use: the standard library and the runs room.
"""
from __future__ import annotations

import xml.etree.ElementTree as ET
from typing import Sequence

from .runs import ModelRun, quantities


def junit_xml(runs: Sequence[ModelRun], name: str = "kinetostat validate") -> ET.ElementTree:
    """One testcase per model x route x quantity; failures as <failure>, skipped routes as
    <skipped>, a route that raised as <error> on each of its quantities."""
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
        for route in run.engines:
            qs = quantities(run.mech, route)
            secs = run.seconds.get(route, 0.0) / max(len(qs), 1)
            rows = {r.quantity: r for r in run.rows if r.route == route}
            for q in qs:
                case = ET.SubElement(suite, "testcase", classname=f"{run.stem}.{route}", name=q,
                                     time=f"{secs:.6f}")
                counts["tests"] += 1
                if route in run.errors:
                    ET.SubElement(case, "error", message=run.errors[route], type="RouteError")
                    counts["errors"] += 1
                elif route in run.skipped:
                    ET.SubElement(case, "skipped", message=run.skipped[route])
                    counts["skipped"] += 1
                elif q not in rows:
                    ET.SubElement(case, "error", message=f"route {route} returned no row for {q}", type="MissingRow")
                    counts["errors"] += 1
                elif not rows[q].passed:
                    r = rows[q]
                    f = ET.SubElement(case, "failure", type="ToleranceExceeded",
                                      message=f"peak-relative error {r.peak_relative:.3e} > tolerance {r.tolerance:.1e}"
                                      if r.n_compared else "no angle compared (engine returned NaN everywhere)")
                    f.text = (f"max abs {r.max_abs:.6g}, rms relative {r.rms_relative:.3e}, peak {r.peak:.6g}, "
                              f"{r.n_compared} angles compared, {r.n_skipped} left out")
                    counts["failures"] += 1
        t = sum(run.seconds.values())
        total_time += t
        for k, v in counts.items():
            suite.set(k, str(v))
            totals[k] += v
        suite.set("time", f"{t:.6f}")
    for k, v in totals.items():
        root.set(k, str(v))
    root.set("time", f"{total_time:.6f}")
    tree = ET.ElementTree(root)
    ET.indent(tree)
    return tree
