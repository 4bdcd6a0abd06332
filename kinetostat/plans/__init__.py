"""The graphical method drawn: plans as data (`core`), built from the exact solution."""
