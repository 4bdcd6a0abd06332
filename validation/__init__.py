"""Cross-validation of kinetostat against Pinocchio, MuJoCo and pymunk (see compare.py).

May use: kinetostat; each engine adapter its own engine.
"""
