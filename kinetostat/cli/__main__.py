"""`python -m kinetostat.cli ...`: the same command line as `python -m kinetostat`.

May use: `main` of this package only.
"""
import sys

from . import main

sys.exit(main())
