"""`python -m kinetostat ...`: the same command line as the `kinetostat` console script.

May use: the command line (`cli`) only.
"""
import sys

from .cli import main

sys.exit(main())
