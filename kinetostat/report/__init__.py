"""Per-mechanism error reports: the solver against every engine route, and against the seeds.

Rooms: `published` (a model's published values beside the exact ones), `runs` (a validation run, route by
route), `junit` (JUnit XML and JSON of validation runs), `document` (Markdown and HTML), `plots` (matplotlib figures),
`writer` (a model's report folder and the index), `rerun` (a rerun's report folder against an earlier
one), `ci` (a check's line in its model file, GitHub annotations and step summary). The solver never imports this package.

May use: its rooms.
"""
from .junit import junit_xml, validation_json
from .published import PublishedCheck, published_rows
from .rerun import Difference, compare_reports
from .runs import Check, ModelRun, quantities, run_validation
from .writer import MIN_REPORT_STEPS, write_index, write_report

__all__ = ["PublishedCheck", "Check", "ModelRun", "run_validation", "quantities",
           "junit_xml", "validation_json", "write_report", "write_index", "published_rows", "MIN_REPORT_STEPS",
           "compare_reports", "Difference"]
