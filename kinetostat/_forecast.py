"""The estimated time of a long job, said before most of it runs: `Forecast` logs, once the first
item is done, about how long the remaining items will take and which options make the job faster.

May use: the standard library only.
"""
from __future__ import annotations

import logging
import math
import time
from typing import Sequence

#: The clock of every forecast, seconds (a test replaces it).
now = time.perf_counter
#: Seconds from which the remaining items make a long job: its forecast is logged at INFO (shown
#: by the command line unless -q); a shorter job's at DEBUG (-v).
LONG = 30.0


def duration(seconds: float) -> str:
    """A duration for people: "0.03 s", "4.2 s", "40 s", "12 min", "3.5 h"."""
    if seconds < 9.95:
        return f"{seconds:.2g} s"
    if seconds < 59.5:
        return f"{seconds:.0f} s"
    if seconds < 5940:
        return f"{seconds / 60:.0f} min"
    return f"{seconds / 3600:.1f} h"


class Forecast:
    """Counts the items of a job of `total` `items` ("model(s)", "variant(s)"); when the first is
    done (`done`), one line on `logger`: about how long the remaining items will take at the first
    one's pace, and the options that make the job faster (`faster`, left out where none applies);
    at INFO where that is at least LONG seconds, else at DEBUG. With `parallel` workers, the
    items started with the first end about with it, and the rest run `parallel` at a time.
    Nothing for a job of one item."""

    def __init__(self, logger: logging.Logger, total: int, items: str, faster: Sequence[str] = (),
                 parallel: int = 1):
        self.logger, self.total, self.items, self.faster = logger, total, items, tuple(faster)
        self.parallel = max(1, min(parallel, total))
        self.started, self.count = now(), 0

    def done(self, n: int = 1) -> None:
        """`n` more items are done."""
        first = self.count == 0
        self.count += n
        left = self.total - self.count
        if first and left > 0:
            secs = (now() - self.started) / n
            rest = secs * math.ceil(max(left - (self.parallel - 1), 0) / self.parallel)
            hint = f"; faster: {' / '.join(self.faster)}" if self.faster else ""
            self.logger.log(logging.INFO if rest >= LONG else logging.DEBUG,
                            "about %s for the remaining %d %s (%s for the first%s)%s", duration(rest), left,
                            self.items, duration(secs), f", {self.parallel} at a time" if self.parallel > 1 else "",
                            hint)
