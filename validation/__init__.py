"""Cross-validation of kinetostat against Pinocchio, MuJoCo and pymunk (see compare.py)."""
