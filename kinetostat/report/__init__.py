"""Per-mechanism error reports: the solver against every engine route, and against the seeds.

Rooms: `published` (the seeds' numbers beside the exact ones), `runs` (a validation run, route by
route), `junit` (JUnit XML), `document` (Markdown and HTML), `plots` (matplotlib figures),
`writer` (a model's report folder and the index). The solver never imports this package.
"""
from .junit import junit_xml
from .published import PUBLISHED, PublishedSet, PublishedValue, published_rows
from .runs import ModelRun, quantities, run_validation
from .writer import MIN_REPORT_STEPS, write_index, write_report

__all__ = ["PUBLISHED", "PublishedValue", "PublishedSet", "ModelRun", "run_validation", "quantities",
           "junit_xml", "write_report", "write_index", "published_rows", "MIN_REPORT_STEPS"]
