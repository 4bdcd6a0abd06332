"""`python -m kinetostat ...`: the same command line as the `kinetostat` console script."""
import sys

from .cli import main

sys.exit(main())
